#pragma once
// One IMU reading in the body frame (the mounting's rotation applied): the
// accelerometer's specific force, m/s², and, from a unit with a gyroscope,
// the angular rate, rad/s.

#include <Eigen/Core>

namespace adit::slam {

struct ImuSample {
  double t = 0.0;  // s, on the LiDAR clock (imu.time_offset_s removed)
  Eigen::Vector3d specific_force = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_rate = Eigen::Vector3d::Zero();
  bool has_gyro = false;  // an accelerometer alone leaves angular_rate zero
};

}  // namespace adit::slam
