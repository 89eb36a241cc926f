#pragma once
// Wheel odometry for `adit bench odometry`, driven by a session config (the
// `can:`, `wheel_odometry:` and `lidar.extrinsics` sections) through aditd's
// own wheel feed: the encoder log is integrated up front, then each scan gets
// the wheels' motion since the previous scan as a prior, in the sensor frame
// (the bench registers sensor-frame scans; aditd registers body-frame ones).

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "adit/daemon/wheel_feed.hpp"
#include "adit/slam/odometry.hpp"

namespace adit::tools {

struct WheelTrack {
  daemon::WheelHistory history{1 << 20};  // every sample of the log (2.9 h at 100 Hz)
  Eigen::Isometry3d extrinsics = Eigen::Isometry3d::Identity();  // sensor in the body frame
  double distance = 0.0;                   // m the wheels travelled over the log
  std::uint64_t samples = 0;
  std::uint64_t rejected = 0;              // samples the wheel odometry did not trust (slip, glitches)
  std::uint64_t slip_episodes = 0;         // times a wheel lost traction
};

// Throws adit::InputError when the config has no usable wheel odometry.
WheelTrack load_wheel_track(const std::string& config_file);

// The sensor's motion from t0 to t1 by the wheels (nullopt outside the log).
std::optional<slam::MotionPrior> wheel_prior(const WheelTrack& track, double t0, double t1);

}  // namespace adit::tools
