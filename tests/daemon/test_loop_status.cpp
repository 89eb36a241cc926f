// The loop closure's progress for the live status (daemon/loop_status.hpp):
// the loop-closure thread's counts as they are, and the correction at the
// graph's newest keyframe as a distance and an angle.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "adit/daemon/loop_status.hpp"

namespace adit::daemon {
namespace {

TEST(LoopStatus, CountsAsTheyAreAndTheNewestKeyframesCorrection) {
  PipelineStats stats;
  stats.loop_keyframes = 40;
  stats.loop_candidates = 7;
  stats.loops_accepted = 3;
  stats.loops_rejected = 4;
  stats.last_loop_realtime_ns = 1'700'000'000'123'456'789;

  const LoopStatus none = loop_status_of(stats, nullptr, true);
  EXPECT_EQ(none.keyframes, 40);
  EXPECT_EQ(none.candidates, 7);
  EXPECT_EQ(none.accepted, 3);
  EXPECT_EQ(none.rejected, 4);
  EXPECT_EQ(none.last_loop_utime, 1'700'000'000'123'456);
  EXPECT_EQ(none.correction_m, 0.0F) << "no correction posted: none";
  EXPECT_TRUE(none.moves_map);

  // Two keyframes: the graph leaves the first where the odometry put it and
  // moves the second by 0.3 m and 2° of yaw; the newest one's is reported.
  const std::vector<std::int64_t> stamps{1'000'000'000, 2'000'000'000};
  Eigen::Isometry3d odometry_second = Eigen::Isometry3d::Identity();
  odometry_second.translation() = Eigen::Vector3d(5, 0, 0);
  Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
  correction.linear() = Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  correction.translation() = Eigen::Vector3d(0.0, 0.3, 0.0);
  const std::vector<Eigen::Isometry3d> odometry{Eigen::Isometry3d::Identity(), odometry_second};
  const std::vector<Eigen::Isometry3d> graph{Eigen::Isometry3d::Identity(), correction * odometry_second};
  const slam::CorrectionTrack track(stamps, graph, odometry);
  const LoopStatus moved = loop_status_of(stats, &track, false);
  EXPECT_NEAR(moved.correction_m, 0.3, 1e-6);
  EXPECT_NEAR(moved.correction_deg, 2.0, 1e-4);
  EXPECT_FALSE(moved.moves_map);
}

}  // namespace
}  // namespace adit::daemon
