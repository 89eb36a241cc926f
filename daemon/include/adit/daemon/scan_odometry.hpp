#pragma once
// One LiDAR scan to one pose, as aditd's odometry stage runs it and as
// `adit bench odometry` measures it: the scan's points from the sensor frame
// to the body frame (lidar.extrinsics) with their firing times in seconds,
// the wheels' motion prior from the CAN feed and the accelerometer's gravity
// from the IMU source (CAN or Ouster, imu_source.hpp) when configured
// (slam/motion_history.hpp, slam/gravity.hpp), then slam::Odometry. The
// gravity prior needs the wheels' acceleration to remove. Without wheels, an
// IMU with a gyroscope makes the odometry LiDAR-inertial: its readings from
// the previous scan to past the sweep go with the scan (ScanInput::imu).
// Thread-free: it runs on its caller's thread and waits only for
// a replayed CAN log or pcap's IMU to catch up with the scan. No allocation
// per scan after construction.

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "adit/config/config.hpp"
#include "adit/daemon/can_feed.hpp"
#include "adit/daemon/imu_source.hpp"
#include "adit/drivers/lidar/point.hpp"
#include "adit/slam/gyrodometry.hpp"
#include "adit/slam/motion_history.hpp"
#include "adit/slam/odometry.hpp"

namespace adit::daemon {

// The odometry aditd runs for `config`: `base` (slam defaults, or a
// benchmark's settings) with the range limits of the lidar section and room
// for `max_points` per scan (exactly; 0 keeps base's).
slam::OdometryConfig odometry_config_of(const config::Config& config, slam::OdometryConfig base, std::size_t max_points);

// How often the motion sensors helped (only counted when configured).
struct MotionAidCounts {
  std::uint64_t wheel_priors = 0;           // scans registered with the wheels' prior
  std::uint64_t scans_without_wheels = 0;   // wheels configured, but no samples around the scan
  std::uint64_t scans_wheels_held = 0;      // a wheel held for slip over the scan's interval: no wheel prior
  std::uint64_t gyro_priors = 0;            // wheel priors turned by the gyroscope (gyrodometry)
  std::uint64_t gyro_refused = 0;           // a gyroscope axis stuck, or its turn far from the wheels': the wheels' turn kept
  std::uint64_t gyro_still = 0;             // scans over which the wheels stood still: the gyroscope's bias learnt
  std::uint64_t gravity_priors = 0;         // scans registered with the accelerometer's up
  std::uint64_t scans_without_gravity = 0;  // IMU and wheels configured, but no readings or not gravity-sized
};

class ScanOdometry {
 public:
  // `can`: the CAN feed (wheels, and an IMU with imu.source can), or null;
  // `imu`: the IMU source (the CAN feed itself, or the Ouster's), or null.
  // `idle` is called while a replayed source lags the scan: it beats the
  // caller's heartbeat and returns false to stop waiting.
  // `keeping_up` (empty: always) is slam::Odometry's: whether no scan waits
  // behind the one in hand, for the searches (docs/decisions/044).
  ScanOdometry(const config::Config& config, const slam::OdometryConfig& odometry, CanFeed* can, ImuSource* imu,
               std::function<bool()> idle, std::function<bool()> keeping_up = {});
  // The CAN feed's own IMU, if it has one.
  ScanOdometry(const config::Config& config, const slam::OdometryConfig& odometry, CanFeed* can,
               std::function<bool()> idle)
      : ScanOdometry(config, odometry, can, can != nullptr && can->has_imu() ? can : nullptr, std::move(idle)) {}

  const slam::OdometryResult& process(const drivers::LidarScan& scan);

  // The last scan in the body frame, with each point's time after the scan's start (s).
  std::span<const Eigen::Vector3f> body_points() const { return body_points_; }
  std::span<const float> body_times() const { return body_times_; }
  double registration_ms() const { return registration_ms_; }
  // The odometry itself: its local map, its last registered scan, its up,
  // and anchoring it to a prior map (slam::Odometry::anchor_to_prior).
  slam::Odometry& odometry() { return odometry_; }
  const Eigen::Isometry3f& extrinsic() const { return extrinsic_; }  // the sensor in the body frame
  const slam::Odometry& odometry() const { return odometry_; }  // slam::Odometry::process, last scan
  const MotionAidCounts& counts() const { return counts_; }
  // The wheels' prior the last scan was registered with (turned by the
  // gyroscope with gyrodometry), or nullopt; and the gyroscope's bias learnt.
  const std::optional<slam::MotionPrior>& wheel_prior() const { return wheel_prior_; }
  const slam::GyroBias& gyro_bias() const { return gyro_bias_; }
  // The IMU the odometry reads (its readings, mounting and stats), or null.
  const ImuSource* imu() const { return imu_; }
  // The LiDAR-inertial filter's state after the last scan it corrected (result().inertial).
  const slam::InertialState& inertial_state() const { return odometry_.inertial().state(); }
  const slam::Matrix18d& inertial_covariance() const { return odometry_.inertial().covariance(); }

 private:
  std::optional<slam::MotionPrior> wheel_prior_for(double previous, double t);
  slam::MotionPrior turned_by_gyro(const slam::MotionPrior& wheels, double previous, double t);
  std::optional<slam::UpMeasurement> up_for(std::int64_t stamp_ns, float sweep_s);

  static constexpr double kSpeedHalfWindow_s = 0.05;  // the wheels' speed: central differences over ±50 ms

  slam::Odometry odometry_;
  Eigen::Isometry3f extrinsic_;
  CanFeed* can_;
  bool wheels_;
  ImuSource* imu_;
  double gravity_sigma_rad_;
  std::function<bool()> idle_;
  double previous_scan_s_ = 0.0;  // the last scan's start (s): the wheels' and the IMU's readings since
  std::vector<slam::ImuSample> imu_samples_;  // reserved only with a gyroscope
  bool gyrodometry_ = false;                  // wheels and a gyroscope, imu.gyro_with_wheels
  slam::GyroNoise gyro_noise_;
  slam::GyroBias gyro_bias_{gyro_noise_};
  std::vector<slam::ImuSample> gyro_samples_;  // reserved only for gyrodometry
  std::vector<Eigen::Vector3f> body_points_;
  std::vector<float> body_times_;
  slam::OdometryResult result_;
  double registration_ms_ = 0.0;
  MotionAidCounts counts_;
  std::optional<slam::MotionPrior> wheel_prior_;
};

}  // namespace adit::daemon
