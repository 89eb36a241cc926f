// Real recordings in the formats the readers claim: TUM RGB-D ground truth at
// 100 Hz against an estimate at ~30 Hz, and EuRoC's CSV ground truth.

#include <cmath>

#include <gtest/gtest.h>

#include "adit/eval/associate.hpp"
#include "brute_nearest.hpp"
#include "adit/eval/trajectory_io.hpp"
#include "shared_data.hpp"

namespace adit::eval {
namespace {
using slam::Pose;
using slam::Trajectory;

TEST(AssociateRealData, TumFr1XyzGroundTruthAt100HzAgainstEstimateAt30Hz) {
  ADIT_REQUIRE_SHARED_DATA(dir, "trajectories/tum-fr1-xyz");
  const Trajectory gt = read_tum(dir / "freiburg1_xyz-groundtruth.txt");
  const Trajectory est = read_tum(dir / "freiburg1_xyz-rgbdslam.txt");
  ASSERT_GT(gt.size(), 2.5 * static_cast<double>(est.size()));  // 100 Hz vs ~30 Hz
  const double max_diff = 0.01;
  const Associated a = associate(gt, est, max_diff);
  // Every estimate pose whose nearest ground-truth stamp is within max_diff is
  // matched to exactly that pose; no other pose is matched.
  std::size_t expected = 0;
  std::size_t k = 0;
  for (std::size_t j = 0; j < est.size(); ++j) {
    const std::size_t i = brute_nearest(gt.stamps, est.stamps[j]);
    if (std::abs(gt.stamps[i] - est.stamps[j]) > max_diff) continue;
    ++expected;
    ASSERT_LT(k, a.pairs.size());
    EXPECT_EQ(a.pairs[k], (IndexPair{i, j}));
    ++k;
  }
  EXPECT_EQ(a.pairs.size(), expected);
  EXPECT_GT(a.pairs.size(), est.size() * 9 / 10);
  ASSERT_EQ(a.ref.size(), a.pairs.size());
  EXPECT_TRUE(a.ref.front().isApprox(gt.poses[a.pairs.front().first]));
  EXPECT_TRUE(a.est.back().isApprox(est.poses[a.pairs.back().second]));
}

TEST(ReadEurocCsvRealData, V102GroundTruthReads) {
  ADIT_REQUIRE_SHARED_DATA(dir, "trajectories/euroc-v102");
  const Trajectory gt = read_euroc_csv(dir / "V102_groundtruth.csv");
  // One header line, the rest are 200 Hz poses over about 83.5 s.
  EXPECT_EQ(gt.size(), 16702u);
  EXPECT_NEAR((gt.stamps.back() - gt.stamps.front()) / static_cast<double>(gt.size() - 1), 0.005, 1e-4);
  EXPECT_TRUE(gt.poses.front().translation().isApprox(Eigen::Vector3d(0.515356, 1.996773, 0.971104)));
  for (const Pose& p : gt.poses) ASSERT_NEAR(p.linear().determinant(), 1.0, 1e-9);
  const Trajectory est = read_tum(dir / "V102.txt");
  EXPECT_EQ(est.size(), 807u);
}

}  // namespace
}  // namespace adit::eval
