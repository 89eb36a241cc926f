#pragma once
// Wheel odometry for `adit bench odometry`, driven by a session config (the
// `can:`, `wheel_odometry:` and `lidar.extrinsics` sections, as aditd reads
// them): the encoder log is integrated up front, then each scan gets the
// wheels' motion since the previous scan as a prior, in the sensor frame.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "adit/slam/odometry.hpp"
#include "adit/slam/pose2.hpp"

namespace adit::tools {

struct WheelTrack {
  std::vector<double> t;           // seconds, on the LiDAR clock (time_offset_s removed)
  std::vector<slam::Pose2> pose;   // integrated body pose
  std::vector<double> distance;    // m travelled so far
  Eigen::Isometry3d extrinsics = Eigen::Isometry3d::Identity();  // sensor in the body frame
  std::uint64_t rejected = 0;      // samples the wheel odometry did not trust (slip, glitches)
};

// Throws adit::InputError when the config has no usable wheel odometry.
WheelTrack load_wheel_track(const std::string& config_file);

// The sensor's motion from t0 to t1 by the wheels, with a covariance that
// grows with the distance and the turn (nullopt outside the log).
std::optional<slam::MotionPrior> wheel_prior(const WheelTrack& track, double t0, double t1);

}  // namespace adit::tools
