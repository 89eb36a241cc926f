#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "adit/slam/inertial_filter.hpp"
#include "smooth_motion.hpp"

namespace adit::slam {
namespace {

using test::Motion;
using test::rotation_error_rad;
using test::samples;

TEST(InertialFilter, ExactReadingsIntegrateToTheTruePath) {
  const Motion m;
  InertialFilter filter(InertialConfig{});
  filter.reset(m.state(1.0));
  // 200 Hz over 2 s, propagated in ten pieces of 0.2 s as scans would.
  const std::vector<ImuSample> imu = samples(m, 0.9, 3.2, 200.0);
  for (int k = 1; k <= 10; ++k) ASSERT_TRUE(filter.propagate(imu, 1.0 + 0.2 * k));
  const InertialState& s = filter.state();
  EXPECT_NEAR(s.t, 3.0, 1e-12);
  EXPECT_LT((s.pose.translation() - m.position(3.0)).norm(), 2e-3);
  EXPECT_LT(rotation_error_rad(s.pose.linear(), m.rotation(3.0)), 1e-4);
  EXPECT_LT((s.velocity - m.velocity(3.0)).norm(), 2e-3);
}

TEST(InertialFilter, LeverArmIsRemovedFromTheSpecificForce) {
  // The IMU 0.3 m off the origin of a body turning at 0.8 rad/s feels
  // ω²·r ≈ 0.2 m/s² more: not removed, 0.17 m of error in 1.3 s.
  Motion m;
  const Eigen::Vector3d r(0.3, -0.1, 0.05);
  std::vector<ImuSample> imu = samples(m, 0.0, 1.5, 400.0);
  for (ImuSample& s : imu) {
    constexpr double h = 1e-4;
    const Eigen::Vector3d w = s.angular_rate;
    const auto pose_at = [&m](double u) { return m.pose(u); };
    const Eigen::Vector3d alpha = (test::body_rate(pose_at, s.t + h) - test::body_rate(pose_at, s.t - h)) / (2.0 * h);
    s.specific_force += alpha.cross(r) + w.cross(w.cross(r));
  }
  InertialConfig with_arm;
  with_arm.imu_position = r;
  InertialFilter filter(with_arm);
  filter.reset(m.state(0.1));
  ASSERT_TRUE(filter.propagate(imu, 1.4));
  EXPECT_LT((filter.state().pose.translation() - m.position(1.4)).norm(), 3e-3);
  InertialFilter ignoring(InertialConfig{});
  ignoring.reset(m.state(0.1));
  ASSERT_TRUE(ignoring.propagate(imu, 1.4));
  EXPECT_GT((ignoring.state().pose.translation() - m.position(1.4)).norm(), 0.02);
}

TEST(InertialFilter, PredictedMotionIsTheBodysRelativeMotion) {
  const Motion m;
  InertialFilter filter(InertialConfig{});
  filter.reset(m.state(2.0));
  const std::vector<ImuSample> imu = samples(m, 1.95, 2.2, 200.0);
  std::vector<TimedPose> motion;
  ASSERT_TRUE(filter.predict_motion(imu, 2.1, motion));
  ASSERT_GE(motion.size(), 20U);
  EXPECT_DOUBLE_EQ(motion.front().t, 0.0);
  EXPECT_NEAR(motion.back().t, 0.1, 1e-12);
  for (const TimedPose& p : motion) {
    const Eigen::Isometry3d truth = m.pose(2.0).inverse() * m.pose(2.0 + p.t);
    EXPECT_LT((p.pose.translation() - truth.translation()).norm(), 1e-4) << p.t;
    EXPECT_LT(rotation_error_rad(p.pose.linear(), truth.linear()), 1e-5) << p.t;
  }
  EXPECT_DOUBLE_EQ(filter.state().t, 2.0);  // predicting changes nothing
}

// The filter's arithmetic on an IMU that is exactly its model: no error
// beyond the datasheet's noise (these samples have none at all).
InertialConfig exactly_modelled() {
  InertialConfig config;
  config.gyro_model_error_density = 0.0;
  config.accel_model_error_density = 0.0;
  return config;
}

TEST(InertialFilter, SamplesThatDoNotCoverTheIntervalAreRefused) {
  const Motion m;
  InertialFilter filter(InertialConfig{});
  filter.reset(m.state(1.0));
  std::vector<ImuSample> imu = samples(m, 0.95, 2.0, 100.0);
  EXPECT_FALSE(filter.propagate(imu, 2.5));  // they end 0.5 s early
  imu.erase(imu.begin() + 40, imu.begin() + 50);  // a 0.1 s dropout inside
  EXPECT_FALSE(filter.propagate(imu, 1.9));
  std::vector<TimedPose> motion;
  EXPECT_FALSE(filter.predict_motion(imu, 1.9, motion));
  EXPECT_TRUE(motion.empty());
  EXPECT_DOUBLE_EQ(filter.state().t, 1.0);
  EXPECT_TRUE(filter.propagate(imu, 1.3));
}

// Scans every 0.1 s measuring the true pose with σ 1 cm and 0.1°: the filter
// must find an unknown start velocity, the gyroscope's and the
// accelerometer's biases and gravity's direction from them.
TEST(InertialFilter, PoseUpdatesRevealVelocityBiasesAndGravity) {
  const Motion m;
  const Eigen::Vector3d gyro_bias(0.004, -0.006, 0.003);     // rad/s, 0.2-0.3°/s
  const Eigen::Vector3d accel_bias(0.08, -0.05, 0.1);        // m/s²
  const std::vector<ImuSample> imu = samples(m, 0.0, 31.0, 200.0, gyro_bias, accel_bias);
  InertialFilter filter(exactly_modelled());
  InertialState start = m.state(0.0);
  start.velocity.setZero();  // unknown: the body is moving at 2.5 m/s
  start.gravity = Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitX()) * start.gravity;  // 1.1° off
  Matrix6d pose_covariance = Matrix6d::Zero();
  filter.reset(start, pose_covariance);
  Matrix6d measurement = Matrix6d::Zero();
  measurement.diagonal() << 1e-4, 1e-4, 1e-4, 3e-6, 3e-6, 3e-6;
  double worst_late_position = 0.0;
  for (int k = 1; k <= 300; ++k) {
    const double t = 0.1 * k;
    ASSERT_TRUE(filter.propagate(imu, t));
    if (k > 100)
      worst_late_position = std::max(worst_late_position, (filter.state().pose.translation() - m.position(t)).norm());
    filter.update(m.pose(t), measurement);
  }
  const InertialState& s = filter.state();
  EXPECT_LT((s.velocity - m.velocity(30.0)).norm(), 0.005);
  EXPECT_LT((s.gyro_bias - gyro_bias).norm(), 1e-4);
  EXPECT_LT((s.accel_bias - accel_bias).norm(), 0.01);
  EXPECT_LT(std::acos(std::clamp(s.gravity.normalized().dot(-Eigen::Vector3d::UnitZ()), -1.0, 1.0)), 2e-3);
  // Once settled, the prediction between scans is good to millimetres.
  EXPECT_LT(worst_late_position, 0.005);
  // And the filter says how well it knows them: within 3 σ.
  const Matrix18d& P = filter.covariance();
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(std::abs(s.gyro_bias(i) - gyro_bias(i)), 3.0 * std::sqrt(P(9 + i, 9 + i))) << i;
    EXPECT_LT(std::abs(s.velocity(i) - m.velocity(30.0)(i)), 3.0 * std::sqrt(P(6 + i, 6 + i))) << i;
  }
}

// At rest with an accelerometer bias of 0.05 m/s² the filter does not know:
// integrated alone, 2.5 m in 10 s. Zero-velocity updates every 0.1 s (and no
// pose measurement at all) hold the body still and teach the filter the
// bias, so that it then stands still for a second without them.
TEST(InertialFilter, ZeroVelocityUpdatesHoldARestingBodyAndLearnItsBias) {
  const auto rest = [](double) { return Eigen::Isometry3d::Identity(); };
  std::vector<ImuSample> imu;
  for (int k = 0; k <= 2200; ++k) imu.push_back(test::imu_sample(rest, 0.005 * k, Eigen::Vector3d::Zero(), {0.05, 0.0, 0.0}));
  InertialState start;
  InertialFilter held(exactly_modelled());
  held.reset(start);
  InertialFilter free(exactly_modelled());
  free.reset(start);
  for (int k = 1; k <= 100; ++k) {
    ASSERT_TRUE(held.propagate(imu, 0.1 * k));
    held.update_zero_velocity(0.01);
    EXPECT_LT(held.state().velocity.norm(), 0.01) << "update " << k;
    const double velocity_variance = held.covariance().block<3, 3>(6, 6).diagonal().maxCoeff();
    EXPECT_LT(velocity_variance, 0.01 * 0.01) << "update " << k;
  }
  ASSERT_TRUE(free.propagate(imu, 10.0));
  EXPECT_GT(free.state().pose.translation().norm(), 2.0);
  EXPECT_LT(held.state().pose.translation().norm(), 0.05);
  // Learnt: without updates for the next second it stays within a centimetre.
  const Eigen::Vector3d before = held.state().pose.translation();
  ASSERT_TRUE(held.propagate(imu, 11.0));
  EXPECT_LT((held.state().pose.translation() - before).norm(), 0.01);
}

TEST(InertialFilter, ThePriorIsThePropagatedPoseWithItsCovariance) {
  const Motion m;
  InertialFilter filter(exactly_modelled());
  filter.reset(m.state(0.0));
  const std::vector<ImuSample> imu = samples(m, 0.0, 0.2, 200.0);
  ASSERT_TRUE(filter.propagate(imu, 0.1));
  const PosePrior prior = filter.pose_prior();
  EXPECT_TRUE(prior.mean.isApprox(filter.state().pose));
  // Velocity known to 2 m/s for 0.1 s: about 0.2 m of translation σ, in any frame.
  const Matrix6d covariance = prior.information.inverse();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(std::sqrt(covariance(i, i)), 0.2, 0.02) << i;
  // Rotation: the gyroscope's bias σ (0.01 rad/s) for 0.1 s, 1 mrad.
  for (int i = 3; i < 6; ++i) EXPECT_NEAR(std::sqrt(covariance(i, i)), 1e-3, 2e-4) << i;
}

// The model error widens the rotation's σ as a white rate noise would:
// σ² = (σ_bg·dt)² + density²·dt, with the datasheet's density beside it.
TEST(InertialFilter, ModelErrorAddsToTheDatasheetNoise) {
  const Motion m;
  InertialConfig config;
  config.gyro_model_error_density = 0.02;
  config.noise.gyro_noise_density = 0.01;
  InertialFilter filter(config);
  filter.reset(m.state(0.0));
  ASSERT_TRUE(filter.propagate(samples(m, 0.0, 0.2, 200.0), 0.1));
  const Matrix6d covariance = filter.pose_prior().information.inverse();
  const double expected = std::sqrt(1e-3 * 1e-3 + (0.02 * 0.02 + 0.01 * 0.01) * 0.1);
  for (int i = 3; i < 6; ++i) EXPECT_NEAR(std::sqrt(covariance(i, i)), expected, 0.1 * expected) << i;
}

}  // namespace
}  // namespace adit::slam
