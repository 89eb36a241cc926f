// Gravity's up from an accelerometer (slam/gravity.hpp).
#include <gtest/gtest.h>

#include <cmath>

#include "adit/slam/gravity.hpp"

namespace adit::slam {
namespace {

TEST(Gravity, AStillBodyReadsUpAlongTheSpecificForce) {
  // Pitched 2° nose down: the accelerometer reads gravity's reaction, up, in its own axes.
  const double pitch = 2.0 * M_PI / 180.0;
  const Eigen::Vector3d f = kStandardGravity * Eigen::Vector3d(-std::sin(pitch), 0.0, std::cos(pitch));
  const auto up = measured_up(f, Eigen::Vector3d::Zero(), 0.001);
  ASSERT_TRUE(up.has_value());
  EXPECT_NEAR(up->up.x(), -std::sin(pitch), 1e-12);
  EXPECT_NEAR(up->up.norm(), 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(up->sigma_rad, 0.001) << "no acceleration, no more doubt than the sensor's";
}

TEST(Gravity, TheKinematicAccelerationIsRemovedAndWidensTheDoubt) {
  // Level, turning left at 1 m/s and 0.5 rad/s: 0.5 m/s² to the left on top of gravity.
  const Eigen::Vector3d a(0.0, 0.5, 0.0);
  const Eigen::Vector3d f = a + Eigen::Vector3d(0.0, 0.0, kStandardGravity);
  const auto up = measured_up(f, a, 0.001);
  ASSERT_TRUE(up.has_value());
  EXPECT_NEAR(up->up.y(), 0.0, 1e-12);
  EXPECT_NEAR(up->sigma_rad, std::hypot(0.001, kAccelerationResidualShare * 0.5 / kStandardGravity), 1e-12);
  // Not removed, the same reading would tilt the up by 2.9°.
  const auto raw = measured_up(f, Eigen::Vector3d::Zero(), 0.001);
  ASSERT_TRUE(raw.has_value());
  EXPECT_NEAR(std::asin(raw->up.y()) * 180.0 / M_PI, 2.92, 0.01);
}

TEST(Gravity, AReadingThatIsNotGravitySizedIsRefused) {
  EXPECT_FALSE(measured_up(Eigen::Vector3d(0.0, 0.0, 0.3 * kStandardGravity), Eigen::Vector3d::Zero(), 0.001))
      << "falling";
  EXPECT_FALSE(measured_up(Eigen::Vector3d(0.0, 0.0, 2.0 * kStandardGravity), Eigen::Vector3d::Zero(), 0.001))
      << "a shock";
  EXPECT_FALSE(measured_up(Eigen::Vector3d(NAN, 0.0, kStandardGravity), Eigen::Vector3d::Zero(), 0.001));
  EXPECT_TRUE(measured_up(Eigen::Vector3d(0.0, 0.0, 1.04 * kStandardGravity), Eigen::Vector3d::Zero(), 0.001));
}

}  // namespace
}  // namespace adit::slam
