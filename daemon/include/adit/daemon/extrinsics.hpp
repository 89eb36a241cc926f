#pragma once
// A configured rigid transform (config::Transform: xyz in metres, roll-pitch-
// yaw in degrees applied Z·Y·X) as an isometry: the sensor's pose in the body
// frame for `lidar.extrinsics`.

#include <cmath>

#include <Eigen/Geometry>

#include "adit/config/config.hpp"

namespace adit::daemon {

inline Eigen::Isometry3d isometry_of(const config::Transform& t) {
  const double k = M_PI / 180.0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(t.rpy_deg[2] * k, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(t.rpy_deg[1] * k, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(t.rpy_deg[0] * k, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() << t.xyz_m[0], t.xyz_m[1], t.xyz_m[2];
  return T;
}

}  // namespace adit::daemon
