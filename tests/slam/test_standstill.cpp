#include <gtest/gtest.h>

#include "adit/slam/standstill.hpp"

namespace adit::slam {
namespace {

constexpr double kDt = 0.1;

// A registration that moved the body by `motion` (body twist [ρ; φ]) from the identity.
RegistrationResult registered(const Vector6d& motion) {
  RegistrationResult r;
  r.pose = exp_se3(motion);
  return r;
}

Vector6d twist(double x, double y, double z, double rx = 0.0, double ry = 0.0, double rz = 0.0) {
  Vector6d v;
  v << x, y, z, rx, ry, rz;
  return v;
}

// The same, registered in a corridor along x: that axis is the degenerate one.
RegistrationResult registered_in_corridor(const Vector6d& motion) {
  RegistrationResult r = registered(motion);
  r.degenerate = true;
  r.weakest_direction = twist(1.0, 0.0, 0.0);
  return r;
}

const Eigen::Isometry3d kFrom = Eigen::Isometry3d::Identity();
const Eigen::Vector3d kSlow(0.05, 0.0, 0.0);  // the filter's velocity, m/s
const Eigen::Vector3d kNoChange(0.002, 0.0, 0.0);  // what the IMU added to it since the last scan

TEST(Standstill, AScanThatSeesNoMotionIsStill) {
  const StandstillConfig config;
  EXPECT_TRUE(appears_still(kFrom, registered(twist(0.001, -0.001, 0.0005, 0.0, 0.0, 0.001)), kDt, kSlow, kNoChange, config));
}

TEST(Standstill, MotionTheScanSeesIsNotStill) {
  const StandstillConfig config;  // 0.03 m/s and 0.02 rad/s: 3 mm and 2 mrad in 0.1 s
  EXPECT_FALSE(appears_still(kFrom, registered(twist(0.0, 0.004, 0.0)), kDt, kSlow, kNoChange, config));
  EXPECT_FALSE(appears_still(kFrom, registered(twist(0.0, 0.0, 0.0, 0.0, 0.0, 0.003)), kDt, kSlow, kNoChange, config));
  // The same motions over a second are slow enough.
  EXPECT_TRUE(appears_still(kFrom, registered(twist(0.0, 0.004, 0.0)), 1.0, kSlow, kNoChange, config));
}

// Setting off along a corridor's axis: the scan sees nothing yet, the
// accelerometer does (0.5 m/s² for 0.1 s).
TEST(Standstill, ABodySettingOffIsNotStill) {
  const StandstillConfig config;
  const RegistrationResult along_axis = registered_in_corridor(twist(0.0025, 0.0, 0.0));
  EXPECT_TRUE(appears_still(kFrom, along_axis, kDt, kSlow, kNoChange, config));
  EXPECT_FALSE(appears_still(kFrom, along_axis, kDt, kSlow, Eigen::Vector3d(0.05, 0.0, 0.0), config));
}

TEST(Standstill, TheDegenerateDirectionIsLeftOut) {
  const StandstillConfig config;
  // 2 cm along a corridor's axis: the prediction's, not the scan's.
  EXPECT_FALSE(appears_still(kFrom, registered(twist(0.02, 0.0, 0.0)), kDt, kSlow, kNoChange, config));
  EXPECT_TRUE(appears_still(kFrom, registered_in_corridor(twist(0.02, 0.0, 0.0)), kDt, kSlow, kNoChange, config));
  // Motion across it still counts.
  EXPECT_FALSE(appears_still(kFrom, registered_in_corridor(twist(0.02, 0.01, 0.0)), kDt, kSlow, kNoChange, config));
}

TEST(Standstill, AFilterThatBelievesInMotionIsNotOverruled) {
  const StandstillConfig config;
  EXPECT_FALSE(appears_still(kFrom, registered_in_corridor(twist(0.1, 0.0, 0.0)), kDt, Eigen::Vector3d(1.0, 0.0, 0.0),
                             kNoChange, config));
  StandstillConfig off = config;
  off.enabled = false;
  EXPECT_FALSE(appears_still(kFrom, registered(Vector6d::Zero()), kDt, kSlow, kNoChange, off));
  EXPECT_FALSE(appears_still(kFrom, registered(Vector6d::Zero()), 0.0, kSlow, kNoChange, config));
}

}  // namespace
}  // namespace adit::slam
