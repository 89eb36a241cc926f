// The pose graph's cost at the size: 2 000 keyframes one metre apart
// round a 500 m square driven four times (odometry drifting 0.05°/m), a loop
// edge every 10 keyframes of each later lap to the first (150 loops), solved
// from the drifted odometry on one thread (issue #20: ≤ 1 s in the background).
#include <benchmark/benchmark.h>

#include <cmath>

#include "adit/slam/pose_graph.hpp"
#include "adit/slam/pose_graph_solver.hpp"

namespace adit::slam {
namespace {

Eigen::Isometry3d pose(double x, double y, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << x, y, 0.0;
  return T;
}

Eigen::Isometry3d square(double s) {  // 125 m sides
  s = std::fmod(s, 500.0);
  const int side = static_cast<int>(s / 125.0);
  const double along = s - 125.0 * side;
  const double yaw = side * M_PI / 2;
  const double cx[4] = {0, 125, 125, 0}, cy[4] = {0, 0, 125, 125};
  return pose(cx[side] + along * std::cos(yaw), cy[side] + along * std::sin(yaw), yaw);
}

PoseGraph make_graph() {
  PoseGraph g;
  constexpr int kNodes = 2000;
  const Eigen::Isometry3d bias = pose(0.0, 0.0, 0.05 * M_PI / 180);
  g.nodes.push_back(square(0));
  for (int k = 1; k < kNodes; ++k) {
    const Eigen::Isometry3d motion = square(k - 1).inverse() * square(k);
    g.edges.push_back({static_cast<std::size_t>(k - 1), static_cast<std::size_t>(k), motion * bias,
                       odometry_information(motion), EdgeKind::odometry});
    g.nodes.push_back(g.nodes.back() * motion * bias);
  }
  Vector6d d;
  d << Eigen::Vector3d::Constant(400.0), Eigen::Vector3d::Constant(40000.0);
  for (int k = 500; k < kNodes; k += 10) {
    const int first = k % 500;
    g.edges.push_back({static_cast<std::size_t>(first), static_cast<std::size_t>(k),
                       square(first).inverse() * square(k), d.asDiagonal(), EdgeKind::loop});
  }
  return g;
}

void BM_PoseGraph2000(benchmark::State& state) {
  const PoseGraph start = make_graph();
  PoseGraphSolverConfig config;
  config.max_time_s = 10.0;
  for (auto _ : state) {
    PoseGraph g = start;
    const PoseGraphSolution s = optimize(g, config);
    benchmark::DoNotOptimize(g.nodes.back());
    state.counters["iterations"] = s.iterations;
    state.counters["converged"] = s.converged ? 1 : 0;
    state.counters["end_error_m"] = (g.nodes.back().translation() - square(1999).translation()).norm();
    state.counters["start_error_m"] = (start.nodes.back().translation() - square(1999).translation()).norm();
  }
}
BENCHMARK(BM_PoseGraph2000)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace adit::slam

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
