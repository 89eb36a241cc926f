// Gyrodometry: the wheels' translation with the gyroscope's rotation, and
// the gyroscope's bias learnt while the wheels stand still.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include "adit/slam/gyrodometry.hpp"
#include "adit/slam/wheel_prior.hpp"

namespace adit::slam {
namespace {

// Readings at 200 Hz from t0 to t1 of a body turning at `rate` (body frame), plus `bias`.
std::vector<ImuSample> readings(double t0, double t1, const Eigen::Vector3d& rate, const Eigen::Vector3d& bias) {
  std::vector<ImuSample> out;
  for (double t = t0; t <= t1 + 1e-9; t += 0.005) {
    ImuSample s;
    s.t = t;
    s.angular_rate = rate + bias;
    s.has_gyro = true;
    out.push_back(s);
  }
  return out;
}

TEST(GyroRotation, IntegratesTheRateOverTheIntervalWithTheBiasRemoved) {
  const Eigen::Vector3d bias(0.01, -0.02, 0.003);
  const auto r = readings(99.997, 100.2, Eigen::Vector3d(0.0, 0.0, 1.2), bias);
  // The interval starts and ends between readings: the ends are interpolated.
  const auto rotation = gyro_rotation(r, 100.0, 100.1, bias, 0.05);
  ASSERT_TRUE(rotation.has_value());
  const Eigen::AngleAxisd turn(*rotation);
  EXPECT_NEAR(turn.angle(), 0.12, 1e-9);
  EXPECT_NEAR(turn.axis().z(), 1.0, 1e-9);
  // Without the bias removed the rotation is off by bias·dt.
  const Eigen::AngleAxisd raw(*gyro_rotation(r, 100.0, 100.1, Eigen::Vector3d::Zero(), 0.05));
  EXPECT_NEAR((raw.axis() * raw.angle() - Eigen::Vector3d(0.0, 0.0, 0.12)).norm(), (bias * 0.1).norm(), 1e-4);
}

TEST(GyroRotation, RefusesReadingsThatDoNotCoverTheIntervalOrHaveAGap) {
  const auto r = readings(100.0, 100.2, Eigen::Vector3d(0.0, 0.0, 1.0), Eigen::Vector3d::Zero());
  EXPECT_FALSE(gyro_rotation(r, 99.9, 100.1, Eigen::Vector3d::Zero(), 0.05).has_value()) << "starts before them";
  EXPECT_FALSE(gyro_rotation(r, 100.1, 100.3, Eigen::Vector3d::Zero(), 0.05).has_value()) << "ends after them";
  auto gap = r;
  gap.erase(gap.begin() + 5, gap.begin() + 20);  // 80 ms without a reading
  EXPECT_FALSE(gyro_rotation(gap, 100.0, 100.15, Eigen::Vector3d::Zero(), 0.05).has_value());
  EXPECT_TRUE(gyro_rotation(gap, 100.11, 100.15, Eigen::Vector3d::Zero(), 0.05).has_value()) << "the gap lies before";
  auto accelerometer_only = r;
  for (auto& s : accelerometer_only) s.has_gyro = false;
  EXPECT_FALSE(gyro_rotation(accelerometer_only, 100.0, 100.1, Eigen::Vector3d::Zero(), 0.05).has_value());
}

TEST(GyroStuck, FindsAnAxisThatReadsOneValueThroughTheInterval) {
  auto r = readings(100.0, 100.2, Eigen::Vector3d(0.01, -0.02, 0.3), Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < r.size(); ++i)  // a MEMS unit's noise: every axis moves
    r[i].angular_rate += 1e-4 * Eigen::Vector3d(static_cast<double>(i % 3), static_cast<double>(i % 2),
                                                static_cast<double>(i % 4));
  EXPECT_FALSE(gyro_stuck(r, 100.0, 100.1));
  for (auto& s : r)
    if (s.t > 100.05) s.angular_rate.z() = 0.0;  // z stuck at zero from 100.05 s
  EXPECT_FALSE(gyro_stuck(r, 100.0, 100.1)) << "it moved within the interval";
  EXPECT_TRUE(gyro_stuck(r, 100.1, 100.2));
  EXPECT_FALSE(gyro_stuck(r, 100.1, 100.125)) << "too few readings to tell";
}

TEST(GyroBias, LearnsTheBiasFromStandstillsAndGrowsUncertainBetweenThem) {
  GyroNoise noise;
  noise.rate_density = 1.7e-4;
  noise.bias_walk = 1.9e-5;
  GyroBias bias(noise);
  EXPECT_FALSE(bias.learnt());
  EXPECT_DOUBLE_EQ(bias.sigma(5.0), noise.initial_bias_sigma);
  const Eigen::Vector3d truth(4e-4, -6e-4, 2e-3);
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss(0.0, 1.0);
  // One second still, in scans of 0.1 s: each mean rate has σ density/√0.1.
  for (int k = 0; k < 10; ++k) {
    const double sigma = noise.rate_density / std::sqrt(0.1);
    const Eigen::Vector3d mean = truth + sigma * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
    EXPECT_TRUE(bias.still(mean, 0.1 * k, 0.1 * (k + 1))) << k;
  }
  EXPECT_TRUE(bias.learnt());
  EXPECT_LT((bias.bias() - truth).cwiseAbs().maxCoeff(), 3.0 * bias.sigma(1.0));
  EXPECT_LT(bias.sigma(1.0), 2.5e-4) << "σ density/√T over one second";
  // A minute later the walk has grown it by √60 s · walk.
  EXPECT_NEAR(bias.sigma(61.0), std::hypot(bias.sigma(1.0), noise.bias_walk * std::sqrt(60.0)), 1e-12);
}

TEST(GyroBias, RefusesAStillnessWhoseRateIsATurn) {
  GyroBias bias(GyroNoise{});
  ASSERT_TRUE(bias.still(Eigen::Vector3d(0.0, 0.0, 5e-4), 0.0, 1.0));
  const Eigen::Vector3d learnt = bias.bias();
  // Wheels still at a motion's onset while the body already pitches at 0.01 rad/s.
  EXPECT_FALSE(bias.still(Eigen::Vector3d(0.0, 0.01, 5e-4), 1.0, 1.1));
  EXPECT_EQ(bias.bias(), learnt);
}

TEST(GyroAided, TakesTheWheelsTranslationAndTheGyroscopesRotationWithItsCovariance) {
  // The wheels read 0.1 m forward with a 0.4 % short turn of 0.14 rad.
  const MotionPrior wheels = wheel_motion_prior({0.0, 0.0, 0.0}, {0.0999, 0.007, 0.14 * 0.996}, 0.1);
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.14, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  GyroNoise noise;
  const std::optional<MotionPrior> prior = gyro_aided(wheels, rotation, 0.1, 2e-4, noise);
  ASSERT_TRUE(prior.has_value());
  EXPECT_TRUE(prior->delta.linear().isApprox(rotation, 1e-12));
  EXPECT_TRUE(prior->delta.translation().isApprox(wheels.delta.translation(), 1e-12));
  EXPECT_TRUE((prior->covariance.topLeftCorner<3, 3>().isApprox(wheels.covariance.topLeftCorner<3, 3>())));
  const double density2 = noise.rate_density * noise.rate_density + noise.model_error_density * noise.model_error_density;
  const double variance = density2 * 0.1 + std::pow(2e-4 * 0.1, 2) + std::pow(noise.scale_error * 0.14, 2);
  EXPECT_TRUE((prior->covariance.bottomRightCorner<3, 3>().isApprox(variance * Eigen::Matrix3d::Identity(), 1e-12)));
  EXPECT_TRUE((prior->covariance.topRightCorner<3, 3>().isZero()));
  // Tighter than the wheels' yaw in a turn, and it now bounds roll and pitch as well.
  EXPECT_LT(prior->covariance(5, 5), wheels.covariance(5, 5));
  EXPECT_LT(prior->covariance(3, 3), wheels.covariance(3, 3));
}

TEST(GyroAided, KeepsTheWheelsTurnWhenTheGyroscopeReadsAFastCornerAsStraight) {
  // A gyroscope stuck at zero while the robot turns 0.14 rad in a scan: the
  // wheels' σ is 0.012 rad there, the difference over ten of it.
  const MotionPrior wheels = wheel_motion_prior({0.0, 0.0, 0.0}, {0.0999, 0.007, 0.14}, 0.1);
  EXPECT_FALSE(gyro_aided(wheels, Eigen::Matrix3d::Identity(), 0.1, 2e-4, GyroNoise{}).has_value());
  // Stuck at 0.3 rad/s on a straight: 0.03 rad against the wheels' 0.0055.
  const MotionPrior straight = wheel_motion_prior({0.0, 0.0, 0.0}, {0.1, 0.0, 0.0}, 0.1);
  const Eigen::Matrix3d turning = Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_FALSE(gyro_aided(straight, turning, 0.1, 2e-4, GyroNoise{}).has_value());
  // A wheel slip's 0.01 rad of false turn in a scan is within both.
  const Eigen::Matrix3d slip = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_TRUE(gyro_aided(straight, slip, 0.1, 2e-4, GyroNoise{}).has_value());
}

}  // namespace
}  // namespace adit::slam
