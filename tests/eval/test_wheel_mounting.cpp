// The LiDAR's mounting from a drive: synthetic drives with a known mounting,
// the sensor's poses and the wheels' as each would report them.

#include "adit/eval/wheel_mounting.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "adit/slam/roll_pitch_yaw.hpp"

namespace adit::eval {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

struct Leg {
  double seconds;
  double speed;      // m/s
  double turn_rate;  // rad/s
};

struct Drive {
  slam::Trajectory sensor;
  std::vector<slam::WheelSample> wheels;
};

// The body follows `legs` at 100 Hz; the sensor sits at `mount` on it. The
// sensor's poses carry white noise (`pose_noise` m and rad); the wheels a
// random walk (`wheel_noise` of each step's travel).
Drive drive(const std::vector<Leg>& legs, const Eigen::Isometry3d& mount, double pose_noise = 0.0,
            double wheel_noise = 0.0, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  Drive d;
  slam::Pose2 truth, wheel;
  double t = 0.0, distance = 0.0;
  const double dt = 0.01;
  for (const Leg& leg : legs) {
    for (int k = 0; k < static_cast<int>(leg.seconds / dt); ++k) {
      Eigen::Isometry3d body = Eigen::Isometry3d::Identity();
      body.linear() = slam::rotation_from_rpy(Eigen::Vector3d(0.0, 0.0, truth.theta));
      body.translation() = Eigen::Vector3d(truth.x, truth.y, 0.0);
      Eigen::Isometry3d sensor = body * mount;
      sensor.translation() += pose_noise * Eigen::Vector3d(n(rng), n(rng), n(rng));
      sensor.linear() = sensor.linear() * slam::rotation_from_rpy(pose_noise * Eigen::Vector3d(n(rng), n(rng), n(rng)));
      d.sensor.push_back(t, sensor);
      d.wheels.push_back({t, wheel, distance, false});

      const double ds = leg.speed * dt, dth = leg.turn_rate * dt;
      truth.x += ds * std::cos(truth.theta + dth / 2);
      truth.y += ds * std::sin(truth.theta + dth / 2);
      truth.theta = slam::wrap_angle(truth.theta + dth);
      const double wds = ds * (1.0 + wheel_noise * n(rng));
      const double wdth = dth + wheel_noise * (std::abs(ds) + std::abs(dth)) * n(rng);
      wheel.x += wds * std::cos(wheel.theta + wdth / 2);
      wheel.y += wds * std::sin(wheel.theta + wdth / 2);
      wheel.theta = slam::wrap_angle(wheel.theta + wdth);
      distance += std::abs(wds);
      t += dt;
    }
  }
  return d;
}

// A survey robot's drive: straights, both turns, a spin, 100 s.
std::vector<Leg> survey_drive() {
  return {{10, 1.0, 0.0}, {8, 0.8, 0.3}, {10, 1.0, 0.0}, {8, 0.8, -0.35}, {5, 0.0, 0.6},
          {12, 1.2, 0.0}, {10, 0.6, -0.25}, {10, 1.0, 0.05}, {6, 0.5, 0.5}, {10, 1.0, 0.0}, {11, 0.7, -0.4}};
}

Eigen::Isometry3d mounting(const Eigen::Vector3d& rpy_deg, const Eigen::Vector3d& xyz) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() = slam::rotation_from_rpy(rpy_deg * kDeg);
  m.translation() = xyz;
  return m;
}

double angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

TEST(RollPitchYaw, RoundTripsAndKeepsSmallAnglesSmall) {
  for (const Eigen::Vector3d& rpy : {Eigen::Vector3d(2, -4, -3), Eigen::Vector3d(-170, 80, 179), Eigen::Vector3d(0, 0, 0)}) {
    const Eigen::Vector3d back = slam::rpy_of(slam::rotation_from_rpy(rpy * kDeg)) / kDeg;
    EXPECT_LT((back - rpy).norm(), 1e-9) << rpy.transpose() << " came back as " << back.transpose();
  }
}

TEST(WheelMounting, ATiltedTurnedSensorAndItsLeverArmAreFound) {
  const Eigen::Isometry3d truth = mounting({2.0, -4.0, 3.0}, {0.20, 0.05, 0.45});
  const Drive d = drive(survey_drive(), truth, 0.001, 0.002);
  const MountingResult r = calibrate_mounting(d.sensor, d.wheels, {});
  EXPECT_LT(angle_between(r.rotation, truth.linear()) / kDeg, 0.1);
  EXPECT_NEAR(r.rpy.x() / kDeg, 2.0, 0.05);
  EXPECT_NEAR(r.rpy.y() / kDeg, -4.0, 0.05);
  EXPECT_NEAR(r.rpy.z() / kDeg, 3.0, 0.1);
  EXPECT_NEAR(r.lever_arm.x(), 0.20, 0.01);
  EXPECT_NEAR(r.lever_arm.y(), 0.05, 0.01);
  EXPECT_TRUE(r.lever_arm_observable);
  EXPECT_TRUE(r.yaw_observable);
  EXPECT_GT(r.turning_windows, 20u);
  EXPECT_GT(r.straight_windows, 20u);
  // The standard deviations say how well: small, and the errors within a few of them.
  EXPECT_LT(r.rpy_sd.maxCoeff() / kDeg, 0.05) << r.rpy_sd.transpose() / kDeg;
  EXPECT_LT(r.lever_arm_sd.maxCoeff(), 0.01);
  EXPECT_LT(std::abs(r.lever_arm.x() - 0.20), 4.0 * r.lever_arm_sd.x());
  EXPECT_LT(std::abs(r.rpy.x() / kDeg - 2.0), 4.0 * r.rpy_sd.x() / kDeg);
  EXPECT_LT(r.rms_planar, r.rms_planar_before);
}

TEST(WheelMounting, ASensorHungUpsideDownAndSidewaysIsFoundSo) {
  const Eigen::Isometry3d truth = mounting({180.0, 0.0, 90.0}, {-0.10, 0.0, -0.20});
  const Drive d = drive(survey_drive(), truth, 0.001, 0.001, 2);
  const MountingResult r = calibrate_mounting(d.sensor, d.wheels, {});
  EXPECT_LT(angle_between(r.rotation, truth.linear()) / kDeg, 0.1) << r.rpy.transpose() / kDeg;
  EXPECT_NEAR(r.lever_arm.x(), -0.10, 0.01);
  EXPECT_NEAR(r.lever_arm.y(), 0.0, 0.01);
}

TEST(WheelMounting, WindowsTheWheelsSlippedInAreDropped) {
  const Eigen::Isometry3d truth = mounting({-1.0, 3.0, -2.0}, {0.30, -0.10, 0.50});
  Drive d = drive(survey_drive(), truth, 0.001, 0.001, 3);
  // Three slips: the wheels report 0.4 m and 0.2 rad the body never drove.
  // Everything after a slip is moved rigidly: turned 0.2 rad about where it
  // happened and pushed 0.4 m ahead.
  for (const double at : {20.0, 50.0, 80.0}) {
    const auto slip = std::find_if(d.wheels.begin(), d.wheels.end(), [&](const slam::WheelSample& w) { return w.t >= at; });
    const slam::Pose2 origin = slip->pose;
    const double c = std::cos(0.2), s = std::sin(0.2);
    for (auto w = slip; w != d.wheels.end(); ++w) {
      const double dx = w->pose.x - origin.x, dy = w->pose.y - origin.y;
      w->pose.x = origin.x + 0.4 * std::cos(origin.theta) + c * dx - s * dy;
      w->pose.y = origin.y + 0.4 * std::sin(origin.theta) + s * dx + c * dy;
      w->pose.theta = slam::wrap_angle(w->pose.theta + 0.2);
    }
  }
  const MountingResult r = calibrate_mounting(d.sensor, d.wheels, {});
  EXPECT_GE(r.outliers, 3u);
  EXPECT_LT(angle_between(r.rotation, truth.linear()) / kDeg, 0.15) << r.rpy.transpose() / kDeg;
  EXPECT_NEAR(r.lever_arm.x(), 0.30, 0.02);
  EXPECT_NEAR(r.lever_arm.y(), -0.10, 0.02);
}

TEST(WheelMounting, SpinningOnTheSpotAloneLeavesTheYawUnobserved) {
  const Eigen::Isometry3d truth = mounting({1.0, 1.0, 10.0}, {0.2, 0.0, 0.4});
  const Drive d = drive({{30, 0.0, 0.5}, {30, 0.0, -0.5}}, truth, 0.001, 0.001, 4);
  const MountingResult r = calibrate_mounting(d.sensor, d.wheels, {});
  EXPECT_FALSE(r.yaw_observable);
  EXPECT_EQ(r.straight_windows, 0u);
  // Roll and pitch come from the turns alone.
  const Eigen::Vector3d up_seen = r.rotation.transpose() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d up_true = truth.linear().transpose() * Eigen::Vector3d::UnitZ();
  EXPECT_LT(std::acos(std::min(1.0, up_seen.dot(up_true))) / kDeg, 0.05);
}

TEST(WheelMounting, StraightDrivingAloneIsRefusedWithTheReason) {
  const Drive d = drive({{60, 1.0, 0.0}}, mounting({0, 0, 0}, {0.2, 0, 0.4}));
  try {
    calibrate_mounting(d.sensor, d.wheels, {});
    FAIL() << "a drive that never turns was calibrated";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("never turns"), std::string::npos) << e.what();
  }
}

TEST(WheelMounting, PosesThatDoNotOverlapTheWheelsAreRefused) {
  Drive d = drive(survey_drive(), mounting({0, 0, 0}, {0.2, 0, 0.4}));
  for (double& t : d.sensor.stamps) t += 1000.0;  // another clock
  EXPECT_THROW(calibrate_mounting(d.sensor, d.wheels, {}), std::invalid_argument);
  EXPECT_THROW(calibrate_mounting(slam::Trajectory{}, d.wheels, {}), std::invalid_argument);
}

TEST(WheelMounting, AGapInTheWheelsIsNotBridged) {
  const Eigen::Isometry3d truth = mounting({2.0, -1.0, 5.0}, {0.2, 0.1, 0.4});
  Drive d = drive(survey_drive(), truth, 0.001, 0.001, 5);
  // A bus-off from 30 s to 34 s: the wheels' pose jumps across it, flagged.
  std::vector<slam::WheelSample> kept;
  for (const slam::WheelSample& w : d.wheels) {
    if (w.t > 30.0 && w.t < 34.0) continue;
    kept.push_back(w);
    if (w.t >= 34.0 && kept.size() >= 2 && kept[kept.size() - 2].t <= 30.0) {
      kept.back().after_gap = true;
    }
  }
  for (slam::WheelSample& w : kept)
    if (w.t >= 34.0) w.pose.x += 5.0;  // the re-baselined pose jumps
  const MountingResult with_gap = calibrate_mounting(d.sensor, kept, {});
  EXPECT_EQ(with_gap.outliers, 0u);  // bridged, the 5 m jump would be one
  EXPECT_LT(angle_between(with_gap.rotation, truth.linear()) / kDeg, 0.1);
}

}  // namespace
}  // namespace adit::eval
