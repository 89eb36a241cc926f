#pragma once
// The nominal kinematics of an IMU-driven body, shared by the filter's
// propagation (inertial_filter.cpp) and the pose extrapolated at the IMU's
// rate between scans (imu_extrapolator.cpp): one midpoint step of pose and
// velocity from two readings (Solà 2017, §5.3, the nominal-state kinematics).

#include <utility>

#include <Eigen/Geometry>

#include "adit/slam/inertial_filter.hpp"
#include "adit/slam/lie.hpp"

namespace adit::slam::kinematics {

// The gyroscope's and accelerometer's values at one instant.
struct Reading {
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
};

inline Eigen::Matrix3d exp_so3(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity() + skew(w);
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

// Specific force at the body origin from the IMU's at `r`: a point at r on
// a rotating body accelerates by α×r + ω×(ω×r) more than the origin.
inline Eigen::Vector3d at_origin(const Eigen::Vector3d& force, const Eigen::Vector3d& omega,
                                 const Eigen::Vector3d& alpha, const Eigen::Vector3d& r) {
  return force - omega.cross(omega.cross(r)) - alpha.cross(r);
}

// One midpoint step of the nominal state; returns the bias-corrected mean
// rate and specific force (at the body origin) used, for the covariance.
inline std::pair<Eigen::Vector3d, Eigen::Vector3d> integrate(InertialState& s, const Reading& a, const Reading& b,
                                                             double dt, const Eigen::Vector3d& r) {
  const Eigen::Vector3d wa = a.gyro - s.gyro_bias, wb = b.gyro - s.gyro_bias;
  const Eigen::Vector3d alpha = dt > 0.0 ? Eigen::Vector3d((wb - wa) / dt) : Eigen::Vector3d::Zero();
  const Eigen::Vector3d fa = at_origin(a.force, wa, alpha, r) - s.accel_bias;
  const Eigen::Vector3d fb = at_origin(b.force, wb, alpha, r) - s.accel_bias;
  const Eigen::Vector3d w = 0.5 * (wa + wb);
  const Eigen::Matrix3d Ra = s.pose.linear();
  const Eigen::Matrix3d Rb = Ra * exp_so3(w * dt);
  const Eigen::Vector3d acceleration = 0.5 * (Ra * fa + Rb * fb) + s.gravity;
  s.pose.translation() += s.velocity * dt + 0.5 * acceleration * dt * dt;
  s.velocity += acceleration * dt;
  Eigen::Quaterniond q(Rb);  // keep R orthonormal over many steps
  s.pose.linear() = q.normalized().toRotationMatrix();
  s.t += dt;
  return {w, 0.5 * (fa + fb)};
}

}  // namespace adit::slam::kinematics
