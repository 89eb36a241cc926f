#include <cmath>

#include <gtest/gtest.h>

#include "adit/eval/interpolate.hpp"

namespace adit::eval {
namespace {
using slam::Pose;
using slam::Trajectory;

Pose pose(double x, double yaw) {
  Pose p = Pose::Identity();
  p.translation() = Eigen::Vector3d(x, 2 * x, 0);
  p.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return p;
}

TEST(InterpolatePose, BetweenStampsLinearAndSlerp) {
  Trajectory t;
  t.push_back(10.0, pose(0, 0));
  t.push_back(11.0, pose(1, 0.4));
  t.push_back(13.0, pose(5, 1.0));
  const auto p = interpolate_pose(t, 10.25);
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->isApprox(pose(0.25, 0.1), 1e-12));
  const auto q = interpolate_pose(t, 12.0);  // halfway from 11 to 13
  ASSERT_TRUE(q);
  EXPECT_TRUE(q->isApprox(pose(3, 0.7), 1e-12));
  EXPECT_TRUE(interpolate_pose(t, 13.0)->isApprox(pose(5, 1.0)));
  EXPECT_TRUE(interpolate_pose(t, 10.0)->isApprox(pose(0, 0)));
}

TEST(InterpolatePose, OutsideOrUntimedIsNothing) {
  Trajectory t;
  EXPECT_FALSE(interpolate_pose(t, 0.0));
  t.push_back(1.0, pose(0, 0));
  t.push_back(2.0, pose(1, 0));
  EXPECT_FALSE(interpolate_pose(t, 0.999));
  EXPECT_FALSE(interpolate_pose(t, 2.001));
  EXPECT_FALSE(interpolate_pose(t, std::nan("")));
  t.timed = false;
  EXPECT_FALSE(interpolate_pose(t, 1.5));
}

}  // namespace
}  // namespace adit::eval
