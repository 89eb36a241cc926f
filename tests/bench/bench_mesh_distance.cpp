// Point-to-mesh distance on the simulator's mine scene (~236 k triangles):
// the grid (one by one, and batched in cell order) against trying every
// triangle, per point, in the same run. Points are on the surfaces with 2 cm
// Gaussian noise, in random order (a map's worst case for the cache).

#include <algorithm>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "adit/sim/scene.hpp"
#include "adit/eval/mesh_distance.hpp"

namespace {

using adit::eval::MeshDistance;
using adit::eval::Triangle;

constexpr std::size_t kGridPoints = 1'000'000;
constexpr std::size_t kBrutePoints = 200;

struct Mine {
  std::vector<Triangle> triangles;
  std::vector<Eigen::Vector3d> points;  // kGridPoints
};

const Mine& mine() {
  static const Mine m = [] {
    Mine out;
    const adit::sim::Scene scene = adit::sim::make_mine(1);
    for (const auto& t : scene.mesh.triangles)
      out.triangles.push_back({scene.mesh.vertices[t[0]].cast<double>(), scene.mesh.vertices[t[1]].cast<double>(),
                               scene.mesh.vertices[t[2]].cast<double>()});
    std::mt19937_64 rng(1);
    std::normal_distribution<double> noise(0.0, 0.02);
    for (const auto& p : adit::sim::sample_surface(scene.mesh, 200.0, 1))
      out.points.push_back(p.cast<double>() + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
    std::shuffle(out.points.begin(), out.points.end(), rng);
    out.points.resize(std::min(out.points.size(), kGridPoints));
    return out;
  }();
  return m;
}

const MeshDistance& grid() {
  static const MeshDistance g(mine().triangles, 1.0);
  return g;
}

void BM_Build(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(MeshDistance(mine().triangles, 1.0));
  state.counters["triangles"] = static_cast<double>(mine().triangles.size());
}
BENCHMARK(BM_Build)->Unit(benchmark::kMillisecond);

void BM_GridOneByOne(benchmark::State& state) {
  const auto& points = mine().points;
  for (auto _ : state)
    for (const auto& p : points) benchmark::DoNotOptimize(grid().distance(p));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * points.size()));
}
BENCHMARK(BM_GridOneByOne)->Unit(benchmark::kMillisecond);

void BM_GridBatch(benchmark::State& state) {
  const auto& points = mine().points;
  for (auto _ : state) benchmark::DoNotOptimize(grid().distances(points));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * points.size()));
}
BENCHMARK(BM_GridBatch)->Unit(benchmark::kMillisecond);

void BM_BruteForce(benchmark::State& state) {
  const auto& m = mine();
  for (auto _ : state)
    for (std::size_t i = 0; i < kBrutePoints; ++i)
      benchmark::DoNotOptimize(adit::eval::brute_force_distance(m.triangles, m.points[i]));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kBrutePoints));
}
BENCHMARK(BM_BruteForce)->Unit(benchmark::kMillisecond);

// Prints CPU time per point and the baseline ratio after the usual table (CPU
// time: on a shared host the wall time mostly measures the neighbours).
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs)
      if (!run.error_occurred) ms_[run.benchmark_name()] = run.GetAdjustedCPUTime();
    ConsoleReporter::ReportRuns(runs);
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    const auto per_point = [&](const std::string& name, std::size_t n) {
      const auto it = ms_.find(name);
      return it == ms_.end() ? 0.0 : it->second * 1e6 / static_cast<double>(n);  // ns
    };
    const double one = per_point("BM_GridOneByOne", mine().points.size());
    const double batch = per_point("BM_GridBatch", mine().points.size());
    const double brute = per_point("BM_BruteForce", kBrutePoints);
    fmt::print("CPU per point: grid one by one {:.0f} ns, batch {:.0f} ns, brute force {:.0f} ns\n", one, batch, brute);
    if (batch > 0.0 && brute > 0.0) fmt::print("brute force / grid batch: {:.0f}x\n", brute / batch);
    if (batch > 0.0) fmt::print("5 M points at the batch rate: {:.2f} s\n", 5e6 * batch * 1e-9);
  }

 private:
  std::map<std::string, double> ms_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
