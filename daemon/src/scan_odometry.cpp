// One scan to one pose with the motion priors, on the caller's thread: the
// odometry stage's step and `adit bench odometry`'s. No allocation per scan;
// waits only for a replayed CAN log. (scan_odometry.hpp)
#include "adit/daemon/scan_odometry.hpp"

#include <algorithm>
#include <numbers>

#include "adit/common/clock.hpp"
#include "adit/daemon/extrinsics.hpp"
#include "adit/slam/gravity.hpp"

namespace adit::daemon {

slam::OdometryConfig odometry_config_of(const config::Config& config, slam::OdometryConfig base, std::size_t max_points) {
  base.min_range_m = static_cast<float>(config.lidar.min_range_m);
  base.max_range_m = static_cast<float>(config.lidar.max_range_m);
  // Sized to the configured sensor, not to slam's 400 000 default: the
  // downsampler's table and the registration's buffers follow it (a VLP-16:
  // 116 352, docs/decisions/032-aditd-memory.md).
  if (max_points > 0) base.max_scan_points = max_points;
  // A wheeled platform's traction bounds how far it departs from constant
  // velocity while its wheels are silent (decision 035).
  if (config.wheel_odometry.enabled) base.max_acceleration_mps2 = config.wheel_odometry.max_acceleration_mps2;
  if (config.imu.enabled) {
    base.inertial.noise = {config.imu.gyro_noise_density, config.imu.accel_noise_density, config.imu.gyro_bias_walk,
                           config.imu.accel_bias_walk};
  }
  return base;
}

namespace {

// The IMU's lever arm as its source knows it (the config's, or the Ouster's
// metadata).
slam::OdometryConfig with_imu_position(slam::OdometryConfig odometry, const ImuSource* imu) {
  if (imu != nullptr) odometry.inertial.imu_position = imu->mounting().position_m;
  return odometry;
}

bool has_gyro(const config::ImuSection& imu) {
  return imu.source != config::ImuSource::can || !imu.gyro_x_signal.empty();  // a LiDAR's own IMU has one
}

}  // namespace

ScanOdometry::ScanOdometry(const config::Config& config, const slam::OdometryConfig& odometry, CanFeed* can,
                           ImuSource* imu, std::function<bool()> idle, std::function<bool()> keeping_up)
    : odometry_(with_imu_position(odometry, config.imu.enabled ? imu : nullptr), std::move(keeping_up)),
      extrinsic_(isometry_of(config.lidar.extrinsics).cast<float>()),
      can_(can),
      wheels_(can != nullptr && can->has_wheels()),
      imu_(config.imu.enabled ? imu : nullptr),
      gravity_sigma_rad_(config.imu.gravity_sigma_deg * std::numbers::pi / 180.0),
      idle_(std::move(idle)) {
  // LiDAR-inertial without wheels (drone, handheld). With wheels the tuned
  // wheel and gravity priors stay: the filter with the wheels fused into its
  // prior ends 10x further off on the simulated robot (ODOMETRY.md, Limits).
  if (imu_ != nullptr && has_gyro(config.imu) && !wheels_) {
    imu_samples_.reserve(kImuHistoryCapacity);
  }
  // With wheels, the gyroscope turns their prior (docs/decisions/052).
  if (imu_ != nullptr && has_gyro(config.imu) && wheels_ && config.imu.gyro_with_wheels) {
    gyrodometry_ = true;
    gyro_noise_.rate_density = config.imu.gyro_noise_density;
    gyro_noise_.bias_walk = config.imu.gyro_bias_walk;
    gyro_noise_.model_error_density = odometry.inertial.gyro_model_error_density;
    gyro_noise_.initial_bias_sigma = odometry.inertial.initial_gyro_bias_sigma_radps;
    gyro_noise_.max_gap_s = odometry.inertial.max_sample_gap_s;
    gyro_bias_ = slam::GyroBias(gyro_noise_);
    gyro_samples_.reserve(kImuHistoryCapacity);
  }
  body_points_.reserve(odometry.max_scan_points);
  body_times_.reserve(odometry.max_scan_points);
}

const slam::OdometryResult& ScanOdometry::process(const drivers::LidarScan& scan) {
  body_points_.clear();
  body_times_.clear();
  for (const drivers::LidarPoint& p : scan.points) {
    body_points_.push_back(extrinsic_ * Eigen::Vector3f(p.x, p.y, p.z));
    body_times_.push_back(1e-9F * static_cast<float>(p.time_offset_ns));
  }
  float sweep_s = 0.0F;
  for (const float t : body_times_) sweep_s = std::max(sweep_s, t);
  // The motion sensors' samples up to the sweep's end and a little past it,
  // for the accelerometer's mean over the sweep and the wheels' speed there.
  // A replayed CAN log or pcap is waited for, so a replay as fast as
  // possible still gets its priors. A CAN IMU is the CAN feed: its second
  // catch_up costs nothing.
  const double until = 1e-9 * static_cast<double>(scan.start_time_ns) + sweep_s + kSpeedHalfWindow_s;
  if (can_ != nullptr) can_->catch_up(until, idle_);
  if (imu_ != nullptr) imu_->catch_up(until, idle_);
  const double t = 1e-9 * static_cast<double>(scan.start_time_ns);
  const double previous = previous_scan_s_;
  previous_scan_s_ = t;
  wheel_prior_ = wheel_prior_for(previous, t);
  const std::optional<slam::UpMeasurement> up = up_for(scan.start_time_ns, sweep_s);
  // With a gyroscope: its readings from the previous scan's start to past
  // this sweep's end, for the LiDAR-inertial step.
  imu_samples_.clear();
  if (imu_samples_.capacity() > 0)
    imu_->history().copy_covering(previous > 0.0 ? previous : t, t + sweep_s, imu_samples_);
  const std::int64_t t0 = monotonic_ns();
  result_ = odometry_.process({scan.start_time_ns, body_points_, body_times_, up, imu_samples_}, wheel_prior_);
  registration_ms_ = 1e-6 * static_cast<double>(monotonic_ns() - t0);
  return result_;
}

// The wheels' motion from the previous scan's start (0: none yet) to this
// one's, or nullopt (then odometry predicts with constant velocity).
std::optional<slam::MotionPrior> ScanOdometry::wheel_prior_for(double previous, double t) {
  if (!wheels_ || previous <= 0.0) return std::nullopt;
  std::optional<slam::MotionPrior> prior = can_->wheels().prior(previous, t);
  if (prior && gyrodometry_) prior = turned_by_gyro(*prior, previous, t);
  if (prior) ++counts_.wheel_priors;
  else if (can_->wheels().held(previous, t)) ++counts_.scans_wheels_held;
  else ++counts_.scans_without_wheels;
  return prior;
}

// The wheels' prior from `previous` to `t` with the gyroscope's rotation over
// the same interval, its bias removed; the wheels' own when the readings do
// not cover it, an axis is stuck, or the two disagree beyond their
// covariances (a failed gyroscope). Wheels that stood still teach the bias
// first: the mean rate is then the bias, unless it is a turn (a body turned
// by hand on its wheels).
slam::MotionPrior ScanOdometry::turned_by_gyro(const slam::MotionPrior& wheels, double previous, double t) {
  constexpr double kStillM = 1e-3;         // wheel travel over the interval, m
  constexpr double kStillRad = 1e-3;       // wheel turn over the interval, rad
  constexpr double kMaxBiasRadps = 0.05;   // above this the body turned: not a bias
  imu_->history().copy_covering(previous, t, gyro_samples_);
  const double dt = t - previous;
  if (slam::gyro_stuck(gyro_samples_, previous, t)) {
    ++counts_.gyro_refused;
    return wheels;
  }
  if (wheels.delta.translation().norm() < kStillM && Eigen::AngleAxisd(wheels.delta.linear()).angle() < kStillRad) {
    const auto raw = slam::gyro_rotation(gyro_samples_, previous, t, Eigen::Vector3d::Zero(), gyro_noise_.max_gap_s);
    if (raw) {
      const Eigen::AngleAxisd turn(*raw);
      const Eigen::Vector3d mean_rate = turn.axis() * (turn.angle() / dt);
      if (mean_rate.norm() < kMaxBiasRadps && gyro_bias_.still(mean_rate, previous, t)) ++counts_.gyro_still;
    }
  }
  const auto rotation = slam::gyro_rotation(gyro_samples_, previous, t, gyro_bias_.bias(), gyro_noise_.max_gap_s);
  if (!rotation) return wheels;
  const std::optional<slam::MotionPrior> turned = slam::gyro_aided(wheels, *rotation, dt, gyro_bias_.sigma(t), gyro_noise_);
  ++(turned ? counts_.gyro_priors : counts_.gyro_refused);
  return turned.value_or(wheels);
}

// After wheel_prior_for: gravity's up in the body frame over the sweep, from
// the accelerometer's mean with the wheels' kinematic acceleration removed
// (slam/gravity.hpp), or nullopt. Without wheels there is no acceleration to
// remove: no prior, and nothing counted.
std::optional<slam::UpMeasurement> ScanOdometry::up_for(std::int64_t stamp_ns, float sweep_s) {
  if (imu_ == nullptr || !wheels_) return std::nullopt;
  const double t0 = 1e-9 * static_cast<double>(stamp_ns);
  const double t1 = t0 + std::max(sweep_s, 0.01F);
  const std::optional<Eigen::Vector3d> force = imu_->history().mean(t0, t1);
  const std::optional<Eigen::Vector3d> acceleration = can_->wheels().acceleration(t0, t1, kSpeedHalfWindow_s);
  std::optional<slam::UpMeasurement> up;
  if (force && acceleration) up = slam::measured_up(*force, *acceleration, gravity_sigma_rad_);
  ++(up ? counts_.gravity_priors : counts_.scans_without_gravity);
  return up;
}

}  // namespace adit::daemon
