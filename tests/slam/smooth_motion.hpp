#pragma once
// Test support: a body on a smooth 3D path (position, velocity and attitude
// analytic) and its exact IMU readings (imu_from_motion.hpp), for the
// inertial filter's and the extrapolator's tests.

#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "adit/slam/inertial_filter.hpp"
#include "imu_from_motion.hpp"

namespace adit::slam::test {

// A body on a smooth 3D path, its velocity analytic, its IMU readings from
// imu_from_motion.hpp.
struct Motion {
  Eigen::Vector3d position(double t) const {
    return {3.0 * std::sin(0.5 * t) + 1.0 * t, 2.0 * (1.0 - std::cos(0.4 * t)), 0.3 * std::sin(1.1 * t)};
  }
  Eigen::Vector3d velocity(double t) const {
    return {1.5 * std::cos(0.5 * t) + 1.0, 0.8 * std::sin(0.4 * t), 0.33 * std::cos(1.1 * t)};
  }
  // R(t) = Rz(yaw)·Ry(pitch)·Rx(roll) with smooth angles.
  Eigen::Vector3d angles(double t) const { return {0.2 * std::sin(0.9 * t), 0.15 * std::sin(0.7 * t + 0.3), 0.8 * t}; }
  Eigen::Matrix3d rotation(double t) const {
    const Eigen::Vector3d a = angles(t);
    return (Eigen::AngleAxisd(a.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(a.y(), Eigen::Vector3d::UnitY()) *
            Eigen::AngleAxisd(a.x(), Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
  }
  Eigen::Isometry3d pose(double t) const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = rotation(t);
    T.translation() = position(t);
    return T;
  }
  ImuSample sample(double t, const Eigen::Vector3d& gyro_bias = Eigen::Vector3d::Zero(),
                   const Eigen::Vector3d& accel_bias = Eigen::Vector3d::Zero()) const {
    return imu_sample([this](double u) { return pose(u); }, t, gyro_bias, accel_bias);
  }
  InertialState state(double t) const {
    InertialState s;
    s.t = t;
    s.pose = pose(t);
    s.velocity = velocity(t);
    return s;
  }
};

inline std::vector<ImuSample> samples(const Motion& m, double t0, double t1, double rate,
                                      const Eigen::Vector3d& gyro_bias = Eigen::Vector3d::Zero(),
                                      const Eigen::Vector3d& accel_bias = Eigen::Vector3d::Zero()) {
  std::vector<ImuSample> out;
  for (int k = 0;; ++k) {
    const double t = t0 + k / rate;
    if (t > t1 + 1e-9) break;
    out.push_back(m.sample(t, gyro_bias, accel_bias));
  }
  return out;
}

inline double rotation_error_rad(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

}  // namespace adit::slam::test
