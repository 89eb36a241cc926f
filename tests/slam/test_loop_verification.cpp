#include <gtest/gtest.h>

#include <cmath>

#include "adit/slam/loop_consistency.hpp"
#include "adit/slam/loop_verification.hpp"
#include "loop_scenes.hpp"
#include "synthetic_scenes.hpp"

namespace adit::slam {
namespace {

using test::pose_at;

// The candidate's submap: `world` seen from `candidate`, in its frame.
VoxelHashMap submap_of(const std::vector<Eigen::Vector3f>& world, const Eigen::Isometry3d& candidate, unsigned seed) {
  const LoopVerificationConfig config;
  VoxelHashMap submap(config.submap_voxel_m, config.submap_capacity_voxels, config.submap_point_spacing_m);
  for (int i = 0; i < 3; ++i) add_to_submap(submap, test::scan_of(world, candidate, seed + i), Eigen::Isometry3d::Identity());
  return submap;
}

const std::vector<Eigen::Vector3f>& ring_world() {
  static const std::vector<Eigen::Vector3f> world = test::ring_corridor(30.0F, 40, 11);
  return world;
}

// A revisit 0.4 m and 4° from where the graph puts it: registered, accepted,
// measured within 3 cm and 0.3°.
TEST(LoopVerification, ARevisitWithPillarsIsAcceptedAndMeasured) {
  const Eigen::Isometry3d candidate = pose_at(12.0, 0.0, 0.0);
  const Eigen::Isometry3d query = pose_at(12.8, -0.4, 0.03);
  const Eigen::Isometry3d truth = candidate.inverse() * query;
  const Eigen::Isometry3d guess = truth * pose_at(0.3, 0.25, 4.0 * M_PI / 180);
  const LoopVerification v =
      verify_loop(test::scan_of(ring_world(), query, 21), submap_of(ring_world(), candidate, 30), std::span(&guess, 1));
  ASSERT_EQ(v.verdict, LoopVerdict::accepted) << to_string(v.verdict) << " inliers " << v.registration.inlier_ratio
                                              << " rmse " << v.registration.rmse_m << " cond "
                                              << v.registration.weakest_eigenvalue;
  const Eigen::Isometry3d e = truth.inverse() * v.relative;
  EXPECT_LT(e.translation().norm(), 0.03);
  EXPECT_LT(Eigen::AngleAxisd(e.linear()).angle(), 0.3 * M_PI / 180);
}

// A deliberately wrong candidate in a plain, symmetric tunnel: 10 m further
// along it registers with a fine fit (every stretch of the tunnel looks the
// same), but the axis is unobserved. Refused outright without partial loops;
// with them, accepted as partial with the tunnel's axis free: the 10 m error
// along it carries no information, so it cannot reach the graph.
TEST(LoopVerification, AWrongCandidateInAPlainTunnelSaysNothingAlongTheAxis) {
  const std::vector<Eigen::Vector3f> tunnel = test::tunnel(120'000, 3, 200.0F);
  const Eigen::Isometry3d candidate = pose_at(0.0, 0.0, 0.0);
  const Eigen::Isometry3d query = pose_at(10.0, 0.0, 0.0);
  const Eigen::Isometry3d truth = candidate.inverse() * query;
  const std::vector<Eigen::Isometry3d> guesses{truth * pose_at(-10.0, 0.1, 0.02)};  // "the same place", a little off
  const std::vector<Eigen::Vector3f> scan = test::scan_of(tunnel, query, 41);
  const VoxelHashMap submap = submap_of(tunnel, candidate, 50);
  LoopVerificationConfig strict;
  strict.allow_partial = false;
  const LoopVerification refused = verify_loop(scan, submap, guesses, strict);
  EXPECT_EQ(refused.verdict, LoopVerdict::ill_conditioned) << to_string(refused.verdict);
  EXPECT_GT(refused.registration.inlier_ratio, 0.6);  // it fit: only the conditioning tells

  const LoopVerification v = verify_loop(scan, submap, guesses);
  ASSERT_EQ(v.verdict, LoopVerdict::partial) << to_string(v.verdict);
  EXPECT_GT(std::abs(v.free_axis.x()), 0.95);
  // The measurement's error against the truth, as the graph's residual sees it.
  const Eigen::Isometry3d wrong = truth.inverse() * v.relative;
  EXPECT_GT(std::abs((v.relative.translation() - truth.translation()).x()), 9.0);
  Vector6d e;
  e << v.relative.translation() - truth.translation(), Eigen::AngleAxisd(wrong.linear()).axis() *
                                                            Eigen::AngleAxisd(wrong.linear()).angle();
  EXPECT_LT(e.dot(v.information * e), 11.3);  // within chi-square's 99 %: no pull
  // Across the axis it did register: 0.1 m and 1° of the guess corrected.
  EXPECT_LT(std::abs(v.relative.translation().y() - truth.translation().y()), 0.03);
}

// A symmetric room (no pillars): turned half round it fits as well as
// unturned. Two readings that both pass: ambiguous, refused.
TEST(LoopVerification, TwoReadingsThatBothFitAreAmbiguous) {
  const std::vector<Eigen::Vector3f> room = test::room(60'000, 5, 6.0F, 4.0F, 2.0F, false);
  const Eigen::Isometry3d candidate = pose_at(0.0, 0.0, 0.0);
  const Eigen::Isometry3d query = pose_at(0.2, 0.1, 0.05);
  const std::vector<Eigen::Isometry3d> guesses{candidate.inverse() * query, pose_at(0.2, 0.1, 0.05 + M_PI)};
  const LoopVerification v = verify_loop(test::scan_of(room, query, 61), submap_of(room, candidate, 70), guesses);
  EXPECT_EQ(v.passing_guesses, 2);
  EXPECT_EQ(v.verdict, LoopVerdict::ambiguous) << to_string(v.verdict);
}

// The same room with the heading gate: the graph's guess (the first) holds
// the heading to within the gate, so the half-turned reading is set aside and
// the one the graph allows is measured. A gate that lets both through keeps
// the room ambiguous.
TEST(LoopVerification, TheHeadingGateSetsTheHalfTurnedReadingAside) {
  const std::vector<Eigen::Vector3f> room = test::room(60'000, 5, 6.0F, 4.0F, 2.0F, false);
  const Eigen::Isometry3d candidate = pose_at(0.0, 0.0, 0.0);
  const Eigen::Isometry3d query = pose_at(0.2, 0.1, 0.05);
  const std::vector<Eigen::Isometry3d> guesses{pose_at(0.1, 0.0, 0.0), pose_at(0.2, 0.1, 0.05 + M_PI)};
  LoopVerificationConfig config;
  config.heading_gate_rad = M_PI / 4;
  const LoopVerification v = verify_loop(test::scan_of(room, query, 61), submap_of(room, candidate, 70), guesses, config);
  EXPECT_EQ(v.passing_guesses, 2);
  EXPECT_EQ(v.set_aside, 1);
  ASSERT_EQ(v.verdict, LoopVerdict::accepted) << to_string(v.verdict);
  EXPECT_LT((v.relative.translation() - query.translation()).norm(), 0.03);
  EXPECT_LT(Eigen::AngleAxisd(v.relative.linear().transpose() * query.linear()).angle(), 0.005);
  config.heading_gate_rad = 3.5;  // wider than a half turn: both readings pass the gate
  EXPECT_EQ(verify_loop(test::scan_of(room, query, 61), submap_of(room, candidate, 70), guesses, config).verdict,
            LoopVerdict::ambiguous);
}

// The query is elsewhere (the other side of the ring): little overlap.
TEST(LoopVerification, AnotherPlaceHasNoOverlap) {
  const Eigen::Isometry3d candidate = pose_at(12.0, 0.0, 0.0);
  const Eigen::Isometry3d query = pose_at(12.0, 30.0, M_PI);
  const Eigen::Isometry3d guess = pose_at(0.0, 0.0, 0.0);
  const LoopVerification v =
      verify_loop(test::scan_of(ring_world(), query, 81), submap_of(ring_world(), candidate, 90), std::span(&guess, 1));
  EXPECT_NE(v.verdict, LoopVerdict::accepted) << to_string(v.verdict);
}

// The guard: one loop waits for a witness; a second that agrees accepts
// both; one 2 m off along the corridor disagrees and is rejected.
TEST(LoopGuard, LoopsNeedAWitnessAndAWrongOneIsRejected) {
  std::vector<Eigen::Isometry3d> poses;
  std::vector<double> variance;
  for (int k = 0; k < 100; ++k) {
    poses.push_back(pose_at(k < 50 ? k : 99 - k, 0.0, k < 50 ? 0.0 : M_PI));  // out 49 m and back
    variance.push_back(k * 1e-4);
  }
  auto loop = [&](std::size_t from, std::size_t to, double error_m) {
    return LoopConstraint{from, to, poses[from].inverse() * poses[to] * pose_at(error_m, 0, 0), 0.05};
  };
  LoopGuard guard;
  GuardDecision d = GuardDecision::accepted;
  EXPECT_TRUE(guard.submit(loop(10, 89, 0.0), poses, variance, d).empty());
  EXPECT_EQ(d, GuardDecision::waiting);
  EXPECT_EQ(guard.submit(loop(11, 88, 0.02), poses, variance, d).size(), 2U);
  EXPECT_EQ(d, GuardDecision::accepted);
  EXPECT_TRUE(guard.submit(loop(12, 87, 2.0), poses, variance, d).empty());
  EXPECT_EQ(d, GuardDecision::rejected);
  EXPECT_EQ(guard.accepted().size(), 2U);
  EXPECT_EQ(guard.rejected(), 1U);
  EXPECT_TRUE(guard.submit(loop(13, 86, -0.03), poses, variance, d).size() == 1U);
}

// Consistency follows the odometry's uncertainty between the two loops:
// 0.5 m of disagreement is too much for neighbours, not for loops 40 m apart
// along an uncertain path.
TEST(LoopGuard, PairwiseConsistencyScalesWithTheOdometryBetween) {
  std::vector<Eigen::Isometry3d> poses;
  std::vector<double> tight, loose;
  for (int k = 0; k < 200; ++k) {
    poses.push_back(pose_at(k, 0.0, 0.0));
    tight.push_back(k * 1e-5);
    loose.push_back(k * 5e-3);
  }
  const LoopConstraint a{0, 100, poses[0].inverse() * poses[100], 0.05};
  const LoopConstraint near{1, 101, poses[1].inverse() * poses[101] * pose_at(0.5, 0, 0), 0.05};
  const LoopConstraint far{40, 140, poses[40].inverse() * poses[140] * pose_at(0.5, 0, 0), 0.05};
  EXPECT_FALSE(pairwise_consistent(a, near, poses, tight));
  EXPECT_FALSE(pairwise_consistent(a, far, poses, tight));
  EXPECT_TRUE(pairwise_consistent(a, far, poses, loose));
}

}  // namespace
}  // namespace adit::slam
