#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "adit/eval/wheel_calibration.hpp"

namespace slam = adit::slam;
namespace eval = adit::eval;

namespace {

// A drive with turns both ways, simulated with true parameters; the wheels
// report speeds as a miscalibrated, time-shifted encoder would.
struct Simulated {
  std::vector<eval::WheelSpeedSample> wheels;
  std::vector<eval::PlanarPosition> reference;
};

Simulated simulate(double true_left_scale, double true_right_scale, double true_track, double offset) {
  Simulated s;
  slam::Pose2 pose;
  const double dt = 0.01;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.005);
  for (int i = 0; i <= 12000; ++i) {
    const double t = i * dt;
    const double v = 8.0 + 2.0 * std::sin(0.11 * t);
    const double yaw_rate = 0.25 * std::sin(0.3 * t) + 0.1 * std::sin(0.05 * t);
    // True rim speeds; the encoder reports them divided by its scale error.
    const double vl = v - 0.5 * yaw_rate * true_track;
    const double vr = v + 0.5 * yaw_rate * true_track;
    s.wheels.push_back({t - offset, vl / true_left_scale, vr / true_right_scale});
    if (i % 5 == 0) s.reference.push_back({t, pose.x + noise(rng), pose.y + noise(rng)});
    pose.x += v * dt * std::cos(pose.theta + 0.5 * yaw_rate * dt);
    pose.y += v * dt * std::sin(pose.theta + 0.5 * yaw_rate * dt);
    pose.theta += yaw_rate * dt;
  }
  return s;
}

}  // namespace

TEST(WheelCalibration, RecoversScalesTrackAndTimeOffset) {
  const Simulated s = simulate(1.02, 0.99, 1.7, 0.12);
  eval::CalibrationOptions o;
  o.nominal.track_width = 1.5;
  const eval::CalibrationResult r = eval::calibrate_wheels(s.wheels, s.reference, o);
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(r.left_scale, 1.02, 2e-3);
  EXPECT_NEAR(r.right_scale, 0.99, 2e-3);
  EXPECT_NEAR(r.effective_track, 1.7, 0.01);
  EXPECT_NEAR(r.time_offset, 0.12, 0.01);
  EXPECT_LT(r.rms_heading_after, r.rms_heading_before);
  EXPECT_LT(r.rms_distance_after, r.rms_distance_before);
  EXPECT_LT(r.endpoint_error_after, 0.1 * r.endpoint_error_before);
  EXPECT_GT(r.standard_deviation[2], 0.0);
}

TEST(WheelCalibration, CommonScaleWithoutTimeOffset) {
  const Simulated s = simulate(1.01, 1.01, 1.6, 0.0);
  eval::CalibrationOptions o;
  o.separate_scales = false;
  o.fit_time_offset = false;
  o.nominal.track_width = 1.6;
  const eval::CalibrationResult r = eval::calibrate_wheels(s.wheels, s.reference, o);
  EXPECT_NEAR(r.left_scale, 1.01, 1e-3);
  EXPECT_EQ(r.left_scale, r.right_scale);
  EXPECT_EQ(r.time_offset, 0.0);
  EXPECT_EQ(r.standard_deviation[3], 0.0);
}

TEST(WheelCalibration, TooLittleOverlapIsAnError) {
  const std::vector<eval::WheelSpeedSample> wheels{{0, 1, 1}, {1, 1, 1}};
  const std::vector<eval::PlanarPosition> reference{{100, 0, 0}, {101, 1, 0}};
  EXPECT_THROW(eval::calibrate_wheels(wheels, reference, {}), std::invalid_argument);
}

TEST(WheelCalibration, SkipsSamplesWhoseTimeGoesBackAndRejectsBadOptions) {
  Simulated s = simulate(1.0, 1.0, 1.6, 0.0);
  // Duplicate and out-of-order samples with nonsense speeds must be ignored.
  s.wheels.insert(s.wheels.begin() + 500, {s.wheels[499].t, 99.0, -99.0});
  s.wheels.insert(s.wheels.begin() + 900, {s.wheels[100].t, 99.0, -99.0});
  eval::CalibrationOptions o;
  o.nominal.track_width = 1.6;
  const eval::CalibrationResult r = eval::calibrate_wheels(s.wheels, s.reference, o);
  EXPECT_NEAR(r.left_scale, 1.0, 2e-3);
  EXPECT_NEAR(r.effective_track, 1.6, 0.01);
  o.window = 0.0;
  EXPECT_THROW(eval::calibrate_wheels(s.wheels, s.reference, o), std::invalid_argument);
}
