// Levelling a frame by gravity's up (slam/levelling.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "adit/slam/levelling.hpp"
#include "adit/slam/roll_pitch_yaw.hpp"

namespace adit::slam {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(Levelling, HeightsInTheLevelledFrameAreTheWorldsWhateverTheStartingTilt) {
  for (const Eigen::Vector3d& rpy_deg : {Eigen::Vector3d(0.75, -0.3, 40.0), Eigen::Vector3d(-2.0, 1.5, -170.0),
                                        Eigen::Vector3d(0.0, 0.0, 90.0), Eigen::Vector3d(10.0, 0.0, 0.0)}) {
    // The odometry frame is the first body frame, tilted in the world: p_world = R·p_odometry.
    const Eigen::Matrix3d r = rotation_from_rpy(rpy_deg * kDeg);
    const Eigen::Vector3d up = r.transpose() * Eigen::Vector3d::UnitZ();  // gravity's up, seen in the odometry frame
    const Eigen::Isometry3d level = level_from_up(2.5 * up);           // any length
    EXPECT_NEAR(tilt_of(level), std::acos(r(2, 2)), 1e-12) << rpy_deg.transpose();
    for (const Eigen::Vector3d& p : {Eigen::Vector3d(100.0, 0.0, 0.0), Eigen::Vector3d(-20.0, 35.0, 4.0)})
      EXPECT_NEAR((level * p).z(), (r * p).z(), 1e-9) << rpy_deg.transpose() << " at " << p.transpose();
    EXPECT_NEAR((level.translation()).norm(), 0.0, 0.0) << "turned about the first pose's position";
  }
}

TEST(Levelling, TheHeadingIsKeptToSecondOrder) {
  // Tilted 1° about an axis 30° off x: the frame's x axis, seen from above,
  // turns by θ²/4·sin 2φ (θ the tilt, φ the axis' angle from x): 6.6e-5 rad.
  const Eigen::Vector3d axis(std::cos(30.0 * kDeg), std::sin(30.0 * kDeg), 0.0);
  const Eigen::Vector3d up = Eigen::AngleAxisd(1.0 * kDeg, axis).toRotationMatrix() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d x = level_from_up(up).linear() * Eigen::Vector3d::UnitX();
  const double theta = 1.0 * kDeg;
  EXPECT_NEAR(std::abs(std::atan2(x.y(), x.x())), theta * theta / 4.0 * std::sin(60.0 * kDeg), 1e-7);
  EXPECT_GT(std::abs(std::atan2(x.y(), x.x())), 0.0) << "not zero either: this is a property, not an identity";
  EXPECT_TRUE(level_from_up(Eigen::Vector3d::UnitZ()).isApprox(Eigen::Isometry3d::Identity()));
}

TEST(Levelling, AnUpThatIsNoDirectionOrPointsDownIsRefused) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(level_from_up(Eigen::Vector3d::Zero()), std::invalid_argument);
  EXPECT_THROW(level_from_up(Eigen::Vector3d(0.0, nan, 1.0)), std::invalid_argument);
  EXPECT_THROW(level_from_up(Eigen::Vector3d(0.1, 0.0, -1.0)), std::invalid_argument);
  EXPECT_THROW(level_from_up(Eigen::Vector3d(1.0, 0.0, 0.0)), std::invalid_argument);
}

}  // namespace
}  // namespace adit::slam
