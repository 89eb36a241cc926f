// adit bench loops: what loop closure costs (issue #20's budgets), on the
// keyframes aditd's mapping stage makes from a recording, with the odometry's
// own per-scan time in the same run as the baseline (docs/LOOPS.md "Measured").
//
// 1. The recording goes through aditd's Pipeline (as fast as it goes, loop
//    closure off so that nothing else competes); its keyframes (stamp, map
//    pose, 0.2 m scan: what the loops thread receives) are kept, and the
//    odometry's time per scan is the baseline.
// 2. The keyframes go through slam::LoopCloser on this thread, as aditd's loops
//    thread feeds it (gravity prior with an accelerometer; keyframes beyond the
//    closer's window go to files in a temporary folder). Per keyframe: the
//    descriptor and candidate search; per candidate: the verification (the
//    closer's own clocks, LoopClosureStats; a keyframe with several candidates
//    gives each their mean); per accepted batch: the graph's optimisation.
// 3. A pose graph of N keyframes (default 2 000) one metre apart round a 500 m
//    square driven four times, odometry drifting 0.05°/m, a loop every 10
//    keyframes of each later lap to the first and a gravity prior per keyframe,
//    solved by slam::optimize (the solver that ships) from the drifted odometry.
// Budgets (issue #20): search ≤ 5 ms per keyframe, verification ≤ 30 ms per
// candidate, 2 000-keyframe optimisation ≤ 1 s on one core.

#include "bench_loops.hpp"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/common/clock.hpp"
#include "adit/common/error.hpp"
#include "adit/common/quantile.hpp"
#include "adit/config/load.hpp"
#include "adit/daemon/loop_closure_stage.hpp"
#include "adit/daemon/pipeline.hpp"
#include "adit/slam/loop_closer.hpp"
#include "adit/slam/pose_graph.hpp"
#include "adit/slam/pose_graph_solver.hpp"
#include "pipeline_run.hpp"
#include "temporary_folder.hpp"

namespace adit::tools {
namespace {

constexpr double kSearchBudgetMs = 5.0;
constexpr double kVerificationBudgetMs = 30.0;
constexpr double kGraphBudgetS = 1.0;

struct Options {
  std::string session;
  std::size_t max_keyframes = 0;  // 0 = all
  int graph_keyframes = 2000;
  int graph_runs = 3;
  bool json = false;
  double optimize_every_s = -1.0;  // < 0: the session's configuration
};

Eigen::Isometry3d planar(double x, double y, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << x, y, 0.0;
  return T;
}

Eigen::Isometry3d on_square(double s) {  // 125 m sides, driven anticlockwise
  s = std::fmod(s, 500.0);
  const int side = static_cast<int>(s / 125.0);
  const double along = s - 125.0 * side;
  const double yaw = side * M_PI / 2;
  const double cx[4] = {0, 125, 125, 0}, cy[4] = {0, 0, 125, 125};
  return planar(cx[side] + along * std::cos(yaw), cy[side] + along * std::sin(yaw), yaw);
}

slam::PoseGraph square_graph(int nodes) {
  slam::PoseGraph g;
  const Eigen::Isometry3d bias = planar(0.0, 0.0, 0.05 * M_PI / 180);
  g.nodes.push_back(on_square(0));
  g.gravity.push_back({0, Eigen::Vector3d::UnitZ(), 1.0 / (0.002 * 0.002), 0.0});
  config::Config with_imu;  // the graph of a payload with an accelerometer: gravity priors and the tilt walk, as aditd's
  with_imu.imu.enabled = true;
  g.tilt_walk_rad_per_sqrt_s = daemon::loop_closure_config(with_imu).tilt_walk_rad_per_sqrt_s;
  for (int k = 1; k < nodes; ++k) {
    const Eigen::Isometry3d motion = on_square(k - 1).inverse() * on_square(k);
    const auto from = static_cast<std::size_t>(k - 1), to = static_cast<std::size_t>(k);
    g.edges.push_back({from, to, motion * bias, slam::odometry_information(motion), slam::EdgeKind::odometry});
    g.nodes.push_back(g.nodes.back() * motion * bias);
    g.gravity.push_back({to, Eigen::Vector3d::UnitZ(), 1.0 / (0.002 * 0.002), static_cast<double>(k)});  // 1 m/s
  }
  slam::Vector6d d;
  d << Eigen::Vector3d::Constant(1.0 / (0.05 * 0.05)), Eigen::Vector3d::Constant(1.0 / (0.005 * 0.005));
  for (int k = 500; k < nodes; k += 10) {
    const int first = k % 500;
    g.edges.push_back({static_cast<std::size_t>(first), static_cast<std::size_t>(k),
                       on_square(first).inverse() * on_square(k), d.asDiagonal(), slam::EdgeKind::loop});
  }
  return g;
}

struct Series {
  std::vector<double> ms;
  nlohmann::json json(double budget_ms, double baseline_ms) const {
    if (ms.empty()) return {{"count", 0}};
    const double median = quantile(ms, 0.5);
    nlohmann::json j{{"count", ms.size()},
                     {"median_ms", median},
                     {"p99_ms", quantile(ms, 0.99)},
                     {"max_ms", quantile(ms, 1.0)},
                     {"median_vs_odometry", baseline_ms > 0.0 ? median / baseline_ms : 0.0}};
    if (budget_ms > 0.0) {
      j["budget_ms"] = budget_ms;
      j["p99_within_budget"] = quantile(ms, 0.99) <= budget_ms;
    }
    return j;
  }
  std::string text(const char* name, double budget_ms, double baseline_ms) const {
    if (ms.empty()) return fmt::format("{:<34} none\n", name);
    const double median = quantile(ms, 0.5), p99 = quantile(ms, 0.99);
    const std::string budget = budget_ms > 0.0 ? fmt::format("{:.0f}", budget_ms) : "-";
    const char* verdict = budget_ms <= 0.0 ? "-" : p99 <= budget_ms ? "met" : "NOT met";
    return fmt::format("{:<34} {:>6} {:>10.2f} {:>10.2f} {:>10.2f} {:>8} {:>8} {:>10.2f}x\n", name, ms.size(), median, p99,
                       quantile(ms, 1.0), budget, verdict, baseline_ms > 0.0 ? median / baseline_ms : 0.0);
  }
};

int bench_loops(const Options& o) {
  const std::filesystem::path dir(o.session);
  const std::filesystem::path yaml = dir / "session.yaml";
  if (!std::filesystem::exists(yaml)) throw InputError(yaml.string(), "", "missing (expected a session of adit sim)");
  config::Config config = config::load_config(yaml);
  if (config.lidar.source != config::LidarSource::pcap)
    throw InputError(yaml.string(), "lidar.source", "the bench needs a capture (pcap)");
  config.lidar.replay_speed = 0.0;  // as fast as it goes: a replay waits for each stage, nothing is dropped
  config.threads.lock_memory = false;
  config.map.loop_closure = false;  // the loop closer runs below, alone on this thread
  config.session.products = false;
  if (o.optimize_every_s >= 0.0) config.map.loops_optimize_every_s = o.optimize_every_s;

  // 1. aditd's pipeline: keyframes and the odometry's time per scan.
  daemon::Pipeline pipeline(config, {});
  const PipelineFigures figures = run_pipeline(pipeline);
  const std::vector<slam::Keyframe>& keyframes = pipeline.keyframes();
  if (keyframes.empty()) throw InputError(config.lidar.pcap, "", "the recording gave no keyframes");
  const double odometry_ms = figures.odometry_median_ms;

  // 2. The loop closer, keyframe by keyframe, as aditd's loops thread feeds it.
  const slam::LoopClosureConfig loops = daemon::loop_closure_config(config);
  slam::LoopCloser closer(loops);
  const TemporaryFolder spill("adit-bench-loops-");  // older keyframes go to disk, as aditd's do
  closer.spill_scans_to(spill.path());
  Series search, verification, optimisation, per_keyframe_cpu;
  std::vector<double> iterations;  // of each optimisation in the session
  const std::size_t count = o.max_keyframes > 0 ? std::min(o.max_keyframes, keyframes.size()) : keyframes.size();
  for (std::size_t i = 0; i < count; ++i) {
    const slam::Keyframe& k = keyframes[i];
    const slam::LoopClosureStats before = closer.stats();
    const std::int64_t t0 = thread_cpu_ns();
    closer.add_keyframe(k.stamp_ns, k.pose, k.points);
    per_keyframe_cpu.ms.push_back(1e-6 * static_cast<double>(thread_cpu_ns() - t0));
    const slam::LoopClosureStats& after = closer.stats();
    search.ms.push_back(1e3 * (after.search_s_total - before.search_s_total));
    const std::size_t candidates = after.candidates - before.candidates;
    for (std::size_t c = 0; c < candidates; ++c)
      verification.ms.push_back(1e3 * (after.verification_s_total - before.verification_s_total) /
                                static_cast<double>(candidates));
    if (after.optimizations > before.optimizations) {
      optimisation.ms.push_back(1e3 * after.last_optimization_s);
      iterations.push_back(after.last_optimization_iterations);
    }
  }
  const slam::LoopClosureStats& s = closer.stats();

  // 3. The graph at the size.
  const slam::PoseGraph start = square_graph(o.graph_keyframes);
  slam::PoseGraphSolverConfig solver;
  solver.max_time_s = 30.0;  // measure it, do not cut it at the budget
  Series graph_wall, graph_cpu;
  slam::PoseGraphSolution solution;
  for (int run = 0; run < o.graph_runs; ++run) {
    slam::PoseGraph g = start;
    const std::int64_t w0 = monotonic_ns(), c0 = thread_cpu_ns();
    solution = slam::optimize(g, solver);
    graph_wall.ms.push_back(1e-6 * static_cast<double>(monotonic_ns() - w0));
    graph_cpu.ms.push_back(1e-6 * static_cast<double>(thread_cpu_ns() - c0));
  }

  if (o.json) {
    const nlohmann::json j{
        {"session", o.session},
        {"scans", figures.poses},
        {"keyframes", count},
        {"odometry_ms_per_scan", {{"median", figures.odometry_median_ms}, {"p99", figures.odometry_p99_ms}}},
        {"candidates", s.candidates},
        {"verified", s.verified},
        {"accepted", s.accepted},
        {"search", search.json(kSearchBudgetMs, odometry_ms)},
        {"verification", verification.json(kVerificationBudgetMs, odometry_ms)},
        {"add_keyframe_cpu", per_keyframe_cpu.json(0.0, odometry_ms)},
        {"optimize_every_s", loops.optimize_every_s},
        {"optimisation_in_session", optimisation.json(0.0, odometry_ms)},
        {"optimisation_in_session_total_s", s.optimization_s_total},
        {"optimisation_in_session_iterations",
         {{"median", iterations.empty() ? 0.0 : quantile(iterations, 0.5)},
          {"max", iterations.empty() ? 0.0 : quantile(iterations, 1.0)},
          {"total", s.optimization_iterations_total}}},
        {"graph", {{"keyframes", o.graph_keyframes},
                   {"loops", start.loop_count()},
                   {"converged", solution.converged},
                   {"iterations", solution.iterations},
                   {"wall", graph_wall.json(1e3 * kGraphBudgetS, odometry_ms)},
                   {"cpu", graph_cpu.json(1e3 * kGraphBudgetS, odometry_ms)}}}};
    fmt::print("{}\n", j.dump(2));
    return kExitOk;
  }
  fmt::print("session {}: {} scans, {} keyframes; odometry {:.2f} ms per scan (median), p99 {:.2f} ms: the baseline\n",
             o.session, figures.poses, count, figures.odometry_median_ms, figures.odometry_p99_ms);
  fmt::print("loop closer: {} candidates, {} verified, {} accepted\n\n", s.candidates, s.verified, s.accepted);
  fmt::print("{:<34} {:>6} {:>10} {:>10} {:>10} {:>8} {:>8} {:>11}\n", "", "n", "median ms", "p99 ms", "max ms",
             "budget ms", "p99", "median/odo");
  fmt::print("{}", search.text("descriptor + search, per keyframe", kSearchBudgetMs, odometry_ms));
  fmt::print("{}", verification.text("verification, per candidate", kVerificationBudgetMs, odometry_ms));
  fmt::print("{}", per_keyframe_cpu.text("add_keyframe, thread CPU", 0.0, odometry_ms));
  fmt::print("{}", optimisation.text("graph optimisation in the session", 0.0, odometry_ms));
  if (!iterations.empty())
    fmt::print("  the session's {} optimisations: {:.1f} s in all, {} iterations (median {:.0f}, max {:.0f})\n",
               iterations.size(), s.optimization_s_total, s.optimization_iterations_total, quantile(iterations, 0.5),
               quantile(iterations, 1.0));
  fmt::print("{}", graph_wall.text(fmt::format("{}-keyframe graph, wall", o.graph_keyframes).c_str(), 1e3 * kGraphBudgetS,
                                   odometry_ms));
  fmt::print("{}", graph_cpu.text(fmt::format("{}-keyframe graph, thread CPU", o.graph_keyframes).c_str(),
                                  1e3 * kGraphBudgetS, odometry_ms));
  fmt::print("graph: {} loops, {} after {} iterations\n", start.loop_count(),
             solution.converged ? "converged" : "NOT converged", solution.iterations);
  return kExitOk;
}

}  // namespace

void add_bench_loops_command(CLI::App& bench, int& status) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = bench.add_subcommand(
      "loops", "Loop closure's cost on a simulated session's keyframes (descriptor + search, verification) and a "
               "2 000-keyframe graph's optimisation, against the odometry's time per scan");
  cmd->add_option("--session", o->session, "A session folder of adit sim (session.yaml, lidar.pcap)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--max-keyframes", o->max_keyframes, "Feed at most this many keyframes to the loop closer (0 = all)");
  cmd->add_option("--graph-keyframes", o->graph_keyframes, "Keyframes of the synthetic graph (default 2000)")
      ->check(CLI::Range(2, 100000));
  cmd->add_option("--graph-runs", o->graph_runs, "Times the graph is solved (default 3)")->check(CLI::Range(1, 100));
  cmd->add_option("--optimize-every-s", o->optimize_every_s,
                  "Loops wait this long for the graph's next optimisation (default: map.loops_optimize_every_s)")
      ->check(CLI::Range(0.0, 600.0));
  cmd->add_flag("--json", o->json, "Print the figures as JSON");
  cmd->callback([o, &status] { status = bench_loops(*o); });
}

}  // namespace adit::tools
