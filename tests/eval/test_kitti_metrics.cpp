// APE and RPE on KITTI sequence 00 (ORB-SLAM estimate) against the values a
// widely used evaluation tool published for these exact files.

#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "adit/eval/align.hpp"
#include "adit/eval/ape.hpp"
#include "adit/eval/rpe.hpp"
#include "adit/eval/stats.hpp"
#include "adit/eval/trajectory_io.hpp"
#include "shared_data.hpp"

namespace adit::eval {
namespace {
using slam::Pose;
using slam::Trajectory;

// The reference stats whose "metric" text starts with `prefix`.
nlohmann::json reference_stats(const std::filesystem::path& dir, const std::string& prefix) {
  std::ifstream in(dir / "reference-metrics.json");
  const nlohmann::json doc = nlohmann::json::parse(in);
  for (const auto& result : doc.at("results"))
    if (result.at("metric").get<std::string>().rfind(prefix, 0) == 0) return result.at("stats");
  ADD_FAILURE() << "no reference result starting with " << prefix;
  return {};
}

void expect_stats_match(const Stats& got, const nlohmann::json& want) {
  ASSERT_FALSE(want.empty());
  const auto near = [](double a, double b) { return std::abs(a - b) <= 1e-4 * std::abs(b); };
  EXPECT_PRED2(near, got.rmse, want.at("rmse").get<double>());
  EXPECT_PRED2(near, got.mean, want.at("mean").get<double>());
  EXPECT_PRED2(near, got.median, want.at("median").get<double>());
  EXPECT_PRED2(near, got.std, want.at("std").get<double>());
  EXPECT_PRED2(near, got.min, want.at("min").get<double>());
  EXPECT_PRED2(near, got.max, want.at("max").get<double>());
  EXPECT_PRED2(near, got.sse, want.at("sse").get<double>());
}

class Kitti00 : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto root = test::shared_data_dir();
    if (!root || !std::filesystem::exists(*root / "trajectories/kitti-00"))
      GTEST_SKIP() << "shared data not found: trajectories/kitti-00";
    dir = *root / "trajectories/kitti-00";
    ref = read_kitti(dir / "KITTI_00_gt.txt");
    est = read_kitti(dir / "KITTI_00_ORB.txt");
  }
  std::filesystem::path dir;
  Trajectory ref, est;
};

TEST_F(Kitti00, ReadsAllPoses) {
  EXPECT_EQ(ref.size(), 4541u);
  EXPECT_EQ(est.size(), 4541u);
  EXPECT_FALSE(ref.timed);
}

TEST_F(Kitti00, ApeTranslationAfterSe3AlignmentMatchesReference) {
  const auto fit = align_trajectory(ref.poses, est.poses, Alignment::se3);
  ASSERT_TRUE(fit);
  std::vector<Pose> aligned;
  for (const Pose& p : est.poses) aligned.push_back(fit->apply(p));
  const PoseErrors errors = absolute_pose_errors(ref.poses, aligned);
  expect_stats_match(compute_stats(errors.translation), reference_stats(dir, "APE, translation"));
}

TEST_F(Kitti00, RpeTranslation10mConsecutiveMatchesReference) {
  const RpeSettings settings{10.0, DeltaUnit::metres, false};
  const auto pairs = rpe_pairs(path_distances(est.poses), est.stamps, settings);
  const PoseErrors errors = relative_pose_errors(ref.poses, est.poses, pairs);
  expect_stats_match(compute_stats(errors.translation), reference_stats(dir, "RPE, translation"));
}

TEST_F(Kitti00, RpeRotation100mConsecutiveMatchesReference) {
  const RpeSettings settings{100.0, DeltaUnit::metres, false};
  const auto pairs = rpe_pairs(path_distances(est.poses), est.stamps, settings);
  const PoseErrors errors = relative_pose_errors(ref.poses, est.poses, pairs);
  expect_stats_match(compute_stats(errors.rotation_deg), reference_stats(dir, "RPE, rotation angle"));
}

}  // namespace
}  // namespace adit::eval
