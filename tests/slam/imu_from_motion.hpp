#pragma once
// Exact IMU readings of a body moving along a smooth path given as a
// function t -> pose (body in the world, z up): the angular rate from the
// rotation's derivative and the specific force f = Rᵀ·(a − g) from the
// position's second derivative, both by central differences (errors of
// order 1e-7, far below any IMU's).

#include <Eigen/Geometry>

#include "adit/slam/gravity.hpp"
#include "adit/slam/imu_sample.hpp"

namespace adit::slam::test {

template <typename PoseAt>
Eigen::Vector3d body_rate(const PoseAt& pose_at, double t) {
  constexpr double h = 1e-5;
  const Eigen::AngleAxisd d(pose_at(t - h).linear().transpose() * pose_at(t + h).linear());
  return d.angle() * d.axis() / (2.0 * h);
}

template <typename PoseAt>
Eigen::Vector3d world_velocity(const PoseAt& pose_at, double t) {
  constexpr double h = 1e-5;
  return (pose_at(t + h).translation() - pose_at(t - h).translation()) / (2.0 * h);
}

template <typename PoseAt>
ImuSample imu_sample(const PoseAt& pose_at, double t, const Eigen::Vector3d& gyro_bias = Eigen::Vector3d::Zero(),
                     const Eigen::Vector3d& accel_bias = Eigen::Vector3d::Zero()) {
  constexpr double h = 1e-3;
  const Eigen::Vector3d a =
      (pose_at(t + h).translation() - 2.0 * pose_at(t).translation() + pose_at(t - h).translation()) / (h * h);
  ImuSample s;
  s.t = t;
  s.angular_rate = body_rate(pose_at, t) + gyro_bias;
  s.specific_force = pose_at(t).linear().transpose() * (a + Eigen::Vector3d(0.0, 0.0, kStandardGravity)) + accel_bias;
  s.has_gyro = true;
  return s;
}

}  // namespace adit::slam::test
