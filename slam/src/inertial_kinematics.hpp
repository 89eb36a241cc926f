#pragma once
// The kinematics of an IMU-driven body, shared by the filter's propagation
// (inertial_filter.cpp) and the pose extrapolated at the IMU's rate between
// scans (imu_extrapolator.cpp), and the gyroscope's rotation for a wheeled
// robot's prior (gyrodometry.cpp): readings interpolated over an interval, one
// midpoint step of pose and velocity from two readings (Solà 2017, §5.3, the
// nominal-state kinematics), and the error state's covariance carried through
// it (§5.3.3).

#include <algorithm>
#include <span>
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

// The samples at `tau`: linear between the two around it, the nearest held
// beyond the ends. `j` walks forward with tau (samples[j].t <= tau).
inline Reading reading_at(std::span<const ImuSample> samples, std::size_t& j, double tau) {
  while (j + 1 < samples.size() && samples[j + 1].t <= tau) ++j;
  const ImuSample& a = samples[j];
  if (tau <= a.t || j + 1 == samples.size()) return {a.angular_rate, a.specific_force};
  const ImuSample& b = samples[j + 1];
  const double s = (tau - a.t) / (b.t - a.t);
  return {a.angular_rate + s * (b.angular_rate - a.angular_rate), a.specific_force + s * (b.specific_force - a.specific_force)};
}

// Whether the samples reach [t0, t1] with no gap over max_gap.
inline bool covers(std::span<const ImuSample> samples, double t0, double t1, double max_gap) {
  if (samples.empty() || samples.front().t > t0 + max_gap || samples.back().t < t1 - max_gap) return false;
  for (std::size_t i = 1; i < samples.size(); ++i) {
    if (samples[i].t <= t0 || samples[i - 1].t >= t1) continue;
    if (!(samples[i].t > samples[i - 1].t) || samples[i].t - samples[i - 1].t > max_gap) return false;
  }
  return true;
}

// Calls step(a, b, dt) for each piece of [t0, t1] between sample times.
template <typename Step>
void for_each_piece(std::span<const ImuSample> samples, double t0, double t1, Step&& step) {
  std::size_t j = 0;
  double tau = t0;
  Reading a = reading_at(samples, j, tau);
  while (tau < t1) {
    double next = t1;
    for (std::size_t k = j; k < samples.size(); ++k)
      if (samples[k].t > tau) {
        next = std::min(next, samples[k].t);
        break;
      }
    const Reading b = reading_at(samples, j, next);
    step(a, b, next - tau);
    a = b;
    tau = next;
  }
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

// Error-state blocks (inertial_filter.hpp): δp, δθ, δv, δb_g, δb_a, δg.
inline constexpr int kP = 0, kTheta = 3, kV = 6, kBg = 9, kBa = 12, kG = 15;

// The error state's covariance through one step of `dt` at attitude R (the
// step's start) with the bias-corrected rate w and specific force f that
// `integrate` returned. Error dynamics (Solà 2017, eq. 269 with local angular
// error), first order in dt: δθ' = exp(−ω dt)·δθ − dt·δb_g, δp' = δp + dt·δv,
// δv' = δv − dt·R[f]×·δθ − dt·R·δb_a + dt·δg; white noise integrated over dt
// (density² · dt; isotropic, so R·Q·Rᵀ = Q), the model error's with the
// datasheet's, and the biases' random walks.
inline void propagate_covariance(Matrix18d& covariance, const Eigen::Matrix3d& R, const Eigen::Vector3d& w,
                                 const Eigen::Vector3d& f, double dt, const InertialConfig& config) {
  const ImuNoise& n = config.noise;
  const double gyro_density2 = n.gyro_noise_density * n.gyro_noise_density +
                               config.gyro_model_error_density * config.gyro_model_error_density;
  const double accel_density2 = n.accel_noise_density * n.accel_noise_density +
                                config.accel_model_error_density * config.accel_model_error_density;
  Matrix18d F = Matrix18d::Identity();
  F.block<3, 3>(kTheta, kTheta) = exp_so3(-w * dt);
  F.block<3, 3>(kTheta, kBg) = -dt * Eigen::Matrix3d::Identity();
  F.block<3, 3>(kP, kV) = dt * Eigen::Matrix3d::Identity();
  F.block<3, 3>(kV, kTheta) = -dt * R * skew(f);
  F.block<3, 3>(kV, kBa) = -dt * R;
  F.block<3, 3>(kV, kG) = dt * Eigen::Matrix3d::Identity();
  covariance = F * covariance * F.transpose();
  covariance.block<3, 3>(kTheta, kTheta).diagonal().array() += gyro_density2 * dt;
  covariance.block<3, 3>(kV, kV).diagonal().array() += accel_density2 * dt;
  covariance.block<3, 3>(kBg, kBg).diagonal().array() += n.gyro_bias_walk * n.gyro_bias_walk * dt;
  covariance.block<3, 3>(kBa, kBa).diagonal().array() += n.accel_bias_walk * n.accel_bias_walk * dt;
}

// The pose block [δp; δθ] (δp in the world) as registration's and pose_t's
// body tangent [ρ; δθ], ρ = Rᵀ·δp.
inline Matrix6d body_pose_covariance(const Matrix18d& covariance, const Eigen::Matrix3d& R) {
  Matrix6d M = Matrix6d::Identity();
  M.topLeftCorner<3, 3>() = R.transpose();
  return M * covariance.topLeftCorner<6, 6>() * M.transpose();
}

}  // namespace adit::slam::kinematics
