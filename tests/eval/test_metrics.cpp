// Stats, RPE pair selection, KITTI drift and end-to-end drift on small cases
// whose answers are computed by hand.

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "adit/eval/ape.hpp"
#include "adit/eval/endpoint.hpp"
#include "adit/eval/kitti_drift.hpp"
#include "adit/eval/pose_error.hpp"
#include "adit/eval/rpe.hpp"
#include "adit/eval/stats.hpp"

namespace adit::eval {
namespace {
using slam::Pose;
using slam::Trajectory;

Pose at(double x, double y, double z, double yaw = 0.0) {
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.translation() = Eigen::Vector3d(x, y, z);
  return p;
}

// A straight drive along x, one pose per metre.
std::vector<Pose> straight(std::size_t n, double step = 1.0) {
  std::vector<Pose> poses;
  for (std::size_t i = 0; i < n; ++i) poses.push_back(at(step * static_cast<double>(i), 0, 0));
  return poses;
}

TEST(Stats, HandComputed) {
  const std::vector<double> v{3, 1, 4, 1, 5, 9};
  const Stats s = compute_stats(v);
  EXPECT_EQ(s.count, 6u);
  EXPECT_DOUBLE_EQ(s.mean, 23.0 / 6.0);
  EXPECT_DOUBLE_EQ(s.median, 3.5);
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 9.0);
  EXPECT_DOUBLE_EQ(s.sse, 133.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(133.0 / 6.0));
  EXPECT_NEAR(s.std, std::sqrt(133.0 / 6.0 - (23.0 / 6.0) * (23.0 / 6.0)), 1e-12);
  EXPECT_DOUBLE_EQ(compute_stats(std::vector<double>{2, 7, 4}).median, 4.0);
  EXPECT_EQ(compute_stats({}).count, 0u);
}

TEST(RotationAngle, SmallAndLargeAngles) {
  for (const double a : {1e-9, 0.3, 3.0, std::numbers::pi})
    EXPECT_NEAR(rotation_angle(Eigen::AngleAxisd(a, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix()), a,
                1e-12);
}

TEST(Ape, TranslationAndRotation) {
  const std::vector<Pose> ref{at(0, 0, 0), at(1, 0, 0)};
  const std::vector<Pose> est{at(0, 3, 4), at(1, 0, 0, std::numbers::pi / 2)};
  const PoseErrors e = absolute_pose_errors(ref, est);
  EXPECT_DOUBLE_EQ(e.translation[0], 5.0);
  EXPECT_DOUBLE_EQ(e.translation[1], 0.0);
  EXPECT_NEAR(e.rotation_deg[1], 90.0, 1e-12);
}

TEST(RpePairs, FramesConsecutiveAndAll) {
  const std::vector<double> d(7, 0.0), t(7, 0.0);
  EXPECT_EQ(rpe_pairs(d, t, {2, DeltaUnit::frames, false}), (std::vector<IndexPair>{{0, 2}, {2, 4}, {4, 6}}));
  EXPECT_EQ(rpe_pairs(d, t, {5, DeltaUnit::frames, true}), (std::vector<IndexPair>{{0, 5}, {1, 6}}));
}

TEST(RpePairs, MetresConsecutiveStartWhereThePathFirstReachesDelta) {
  const std::vector<double> d{0, 1, 2, 3, 4, 5, 6, 7};
  EXPECT_EQ(rpe_pairs(d, d, {3, DeltaUnit::metres, false}), (std::vector<IndexPair>{{3, 6}}));
  EXPECT_EQ(rpe_pairs(d, d, {2, DeltaUnit::metres, false}), (std::vector<IndexPair>{{2, 4}, {4, 6}}));
}

TEST(RpePairs, SecondsConsecutiveStartAtZero) {
  const std::vector<double> t{0, 0.4, 1.1, 1.5, 2.2, 3.0};
  EXPECT_EQ(rpe_pairs(t, t, {1, DeltaUnit::seconds, false}), (std::vector<IndexPair>{{0, 2}, {2, 4}}));
}

TEST(RpePairs, AllPairsBinarySearchEqualsLinearScan) {
  // Irregular steps, including standstills (equal path values).
  std::vector<double> d{0};
  for (int i = 1; i < 400; ++i) d.push_back(d.back() + (i % 7 == 0 ? 0.0 : 0.1 + 0.05 * (i % 5)));
  for (const double delta : {1.0, 5.0, 20.0}) {
    const auto fast = rpe_pairs(d, d, {delta, DeltaUnit::metres, true, 0.1});
    EXPECT_EQ(fast, rpe_pairs_all_naive(d, delta, 0.1 * delta)) << delta;
    EXPECT_FALSE(fast.empty());
  }
}

TEST(Rpe, ScaleErrorShowsInTranslationOnly) {
  // The estimate drives 1.1 m for every metre: each 1-frame step is 0.1 m long.
  const std::vector<Pose> ref = straight(5), est = straight(5, 1.1);
  const std::vector<IndexPair> pairs{{0, 1}, {1, 3}};
  const PoseErrors e = relative_pose_errors(ref, est, pairs);
  EXPECT_NEAR(e.translation[0], 0.1, 1e-12);
  EXPECT_NEAR(e.translation[1], 0.2, 1e-12);
  EXPECT_NEAR(e.rotation_deg[0], 0.0, 1e-12);
}

TEST(KittiDrift, OnePercentScaleErrorIsOnePercent) {
  const std::vector<Pose> ref = straight(1001), est = straight(1001, 1.01);
  const auto drift = kitti_drift(ref, est);
  ASSERT_TRUE(drift);
  // Segments start every 10 m; L m needs frame first + L + 1 (strictly beyond L):
  // 100 m has starts 0..890 (90 segments), 800 m has 0..190 (20).
  EXPECT_EQ(drift->by_length[0].segments, 90u);
  EXPECT_EQ(drift->by_length[7].segments, 20u);
  // Each segment spans L + 1 m of reference: error 0.01 (L + 1) / L.
  EXPECT_NEAR(drift->by_length[0].translation_percent, 1.01, 1e-9);
  EXPECT_NEAR(drift->rotation_deg_per_100m, 0.0, 1e-9);
  EXPECT_FALSE(kitti_drift(straight(50), straight(50)));
}

TEST(KittiDrift, ConstantHeadingDriftGivesItsRatePerMetre) {
  // Positions exact, heading off by c per frame (one frame per metre): a
  // segment of L m spans L + 1 frames, so its rotation error is c (L + 1).
  const double c = 1e-4;
  const std::vector<Pose> ref = straight(1001);
  std::vector<Pose> est = ref;
  for (std::size_t i = 0; i < est.size(); ++i)
    est[i].linear() = Eigen::AngleAxisd(c * static_cast<double>(i), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const auto drift = kitti_drift(ref, est);
  ASSERT_TRUE(drift);
  for (const KittiLengthDrift& b : drift->by_length)
    EXPECT_NEAR(b.rotation_deg_per_100m, 100.0 * rad_to_deg(c * (b.length + 1.0)) / b.length, 1e-9) << b.length;
}

TEST(EndpointDrift, HandComputed) {
  // Three sides of a 3 x 4 rectangle: path 3 + 4 + 3 = 10 m.
  const std::vector<Pose> poses{at(0, 0, 0), at(3, 0, 0), at(3, 4, 0), at(0, 4, 0)};
  const EndpointDrift d = endpoint_drift(poses, Eigen::Vector3d(0.0, 4.3, 0.0));
  EXPECT_TRUE(d.estimated_delta.isApprox(Eigen::Vector3d(0, 4, 0)));
  EXPECT_NEAR(d.drift, 0.3, 1e-12);
  EXPECT_NEAR(d.length, 10.0, 1e-12);
  EXPECT_NEAR(d.rate, 0.03, 1e-12);
}

}  // namespace
}  // namespace adit::eval
