#pragma once
// Roll, pitch and yaw as the config writes rotations (`rpy_deg`, applied
// Z·Y·X: R = Rz(yaw) Ry(pitch) Rx(roll), the aerospace convention of
// Diebel, "Representing Attitude", 2006, §5.6), to a rotation and back.

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace adit::slam {

// Radians (roll, pitch, yaw) to R = Rz(yaw) Ry(pitch) Rx(roll).
inline Eigen::Matrix3d rotation_from_rpy(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// The inverse, with pitch in [-pi/2, pi/2] and roll, yaw in (-pi, pi], so a
// small rotation gives small angles (Eigen's eulerAngles puts the first angle
// in [0, pi] and may turn -2° of yaw into 178° with the others flipped).
inline Eigen::Vector3d rpy_of(const Eigen::Matrix3d& r) {
  const double pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  return Eigen::Vector3d(std::atan2(r(2, 1), r(2, 2)), pitch, std::atan2(r(1, 0), r(0, 0)));
}

}  // namespace adit::slam
