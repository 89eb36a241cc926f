#pragma once
// A configured rigid transform (config::Transform: xyz in metres, roll-pitch-
// yaw in degrees applied Z·Y·X) as an isometry: the sensor's pose in the body
// frame for `lidar.extrinsics`.

#include <array>
#include <numbers>

#include <Eigen/Geometry>

#include "adit/config/config.hpp"
#include "adit/slam/roll_pitch_yaw.hpp"

namespace adit::daemon {

// Degrees (the config's roll, pitch, yaw) to the rotation Rz·Ry·Rx.
inline Eigen::Matrix3d rotation_of_rpy_deg(const std::array<double, 3>& rpy_deg) {
  return slam::rotation_from_rpy(Eigen::Vector3d(rpy_deg[0], rpy_deg[1], rpy_deg[2]) * (std::numbers::pi / 180.0));
}

inline Eigen::Isometry3d isometry_of(const config::Transform& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotation_of_rpy_deg(t.rpy_deg);
  T.translation() << t.xyz_m[0], t.xyz_m[1], t.xyz_m[2];
  return T;
}

}  // namespace adit::daemon
