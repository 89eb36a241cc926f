// Trajectory evaluation speed on KITTI 00 (4541 poses). Goal: APE plus RPE in
// under 1 s. Baseline in the same run: all-pairs RPE pair search by a linear
// scan from every pose (O(n^2)) against the binary search on path prefix sums.

#include <map>
#include <string>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "adit/eval/align.hpp"
#include "adit/eval/ape.hpp"
#include "adit/eval/associate.hpp"
#include "adit/eval/kitti_drift.hpp"
#include "adit/eval/path.hpp"
#include "adit/eval/rpe.hpp"
#include "adit/eval/stats.hpp"
#include "adit/eval/trajectory_io.hpp"
#include "shared_data.hpp"

namespace {

using namespace adit::slam;
using namespace adit::eval;

struct Kitti00 {
  std::filesystem::path dir;
  Trajectory ref, est;
  bool ok = false;
};

// Loaded once for all benchmarks.
const Kitti00& kitti00() {
  static const Kitti00 data = [] {
    Kitti00 d;
    const auto root = adit::test::shared_data_dir();
    if (!root || !std::filesystem::exists(*root / "trajectories/kitti-00")) return d;
    d.dir = *root / "trajectories/kitti-00";
    d.ref = read_kitti(d.dir / "KITTI_00_gt.txt");
    d.est = read_kitti(d.dir / "KITTI_00_ORB.txt");
    d.ok = true;
    return d;
  }();
  return data;
}

// What `adit eval traj` computes after reading: SE(3) alignment, APE, RPE
// (10 m consecutive), stats.
double ape_and_rpe(const Trajectory& ref, const Trajectory& est, bool all_pairs) {
  const Associated a = associate(ref, est, 0.01);
  const auto fit = align_trajectory(a.ref, a.est, Alignment::se3);
  std::vector<Pose> aligned;
  aligned.reserve(a.est.size());
  for (const Pose& p : a.est) aligned.push_back(fit->apply(p));
  const PoseErrors ape = absolute_pose_errors(a.ref, aligned);
  const auto pairs = rpe_pairs(path_distances(aligned), a.stamps, {10.0, DeltaUnit::metres, all_pairs});
  const PoseErrors rpe = relative_pose_errors(a.ref, aligned, pairs);
  return compute_stats(ape.translation).rmse + compute_stats(rpe.translation).rmse +
         compute_stats(rpe.rotation_deg).rmse;
}

void BM_Kitti00_ReadAndEvaluate(benchmark::State& state) {
  const Kitti00& k = kitti00();
  if (!k.ok) return state.SkipWithError("shared data not found: trajectories/kitti-00");
  for (auto _ : state) {
    const Trajectory ref = read_kitti(k.dir / "KITTI_00_gt.txt");
    const Trajectory est = read_kitti(k.dir / "KITTI_00_ORB.txt");
    benchmark::DoNotOptimize(ape_and_rpe(ref, est, false));
    benchmark::DoNotOptimize(kitti_drift(ref.poses, est.poses));
  }
}
BENCHMARK(BM_Kitti00_ReadAndEvaluate)->Unit(benchmark::kMillisecond);

void BM_Kitti00_ApeRpeConsecutive(benchmark::State& state) {
  const Kitti00& k = kitti00();
  if (!k.ok) return state.SkipWithError("shared data not found: trajectories/kitti-00");
  for (auto _ : state) benchmark::DoNotOptimize(ape_and_rpe(k.ref, k.est, false));
}
BENCHMARK(BM_Kitti00_ApeRpeConsecutive)->Unit(benchmark::kMillisecond);

void BM_Kitti00_ApeRpeAllPairs(benchmark::State& state) {
  const Kitti00& k = kitti00();
  if (!k.ok) return state.SkipWithError("shared data not found: trajectories/kitti-00");
  for (auto _ : state) benchmark::DoNotOptimize(ape_and_rpe(k.ref, k.est, true));
}
BENCHMARK(BM_Kitti00_ApeRpeAllPairs)->Unit(benchmark::kMillisecond);

void BM_Kitti00_KittiDrift(benchmark::State& state) {
  const Kitti00& k = kitti00();
  if (!k.ok) return state.SkipWithError("shared data not found: trajectories/kitti-00");
  for (auto _ : state) benchmark::DoNotOptimize(kitti_drift(k.ref.poses, k.est.poses));
}
BENCHMARK(BM_Kitti00_KittiDrift)->Unit(benchmark::kMillisecond);

// The pair search alone, 10 m all pairs: prefix sums + binary search...
void BM_AllPairsSearch_PrefixSum(benchmark::State& state) {
  const Kitti00& k = kitti00();
  if (!k.ok) return state.SkipWithError("shared data not found: trajectories/kitti-00");
  const std::vector<double> d = path_distances(k.est.poses);
  for (auto _ : state) benchmark::DoNotOptimize(rpe_pairs(d, k.est.stamps, {10.0, DeltaUnit::metres, true}));
}
BENCHMARK(BM_AllPairsSearch_PrefixSum)->Unit(benchmark::kMillisecond);

// ...and the naive baseline: a linear scan from every pose.
void BM_AllPairsSearch_NaiveScan(benchmark::State& state) {
  const Kitti00& k = kitti00();
  if (!k.ok) return state.SkipWithError("shared data not found: trajectories/kitti-00");
  const std::vector<double> d = path_distances(k.est.poses);
  for (auto _ : state) benchmark::DoNotOptimize(rpe_pairs_all_naive(d, 10.0, 1.0));
}
BENCHMARK(BM_AllPairsSearch_NaiveScan)->Unit(benchmark::kMillisecond);

// Prints the baseline ratios after the usual table.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs)
      if (!run.error_occurred) real_ms_[run.benchmark_name()] = run.GetAdjustedRealTime();
    ConsoleReporter::ReportRuns(runs);
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    ratio("BM_AllPairsSearch_NaiveScan", "BM_AllPairsSearch_PrefixSum", "all-pairs search, naive / prefix-sum");
    ratio("BM_Kitti00_ApeRpeAllPairs", "BM_Kitti00_ApeRpeConsecutive", "APE+RPE, all pairs / consecutive");
    const auto full = real_ms_.find("BM_Kitti00_ReadAndEvaluate");
    if (full != real_ms_.end())
      fmt::print("KITTI 00 read + APE + RPE + KITTI drift: {:.1f} ms (goal < 1000 ms)\n", full->second);
  }

 private:
  void ratio(const std::string& slow, const std::string& fast, const char* what) {
    const auto s = real_ms_.find(slow), f = real_ms_.find(fast);
    if (s != real_ms_.end() && f != real_ms_.end() && f->second > 0.0)
      fmt::print("{}: {:.1f}x\n", what, s->second / f->second);
  }
  std::map<std::string, double> real_ms_;
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
