#include "adit/slam/gyrodometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Dense>

#include "inertial_kinematics.hpp"

namespace adit::slam {

std::optional<Eigen::Matrix3d> gyro_rotation(std::span<const ImuSample> readings, double t0, double t1,
                                             const Eigen::Vector3d& bias, double max_gap_s) {
  if (!(t1 > t0) || !kinematics::covers(readings, t0, t1, max_gap_s)) return std::nullopt;
  for (const ImuSample& r : readings)
    if (!r.has_gyro) return std::nullopt;
  // The filter's midpoint rule (inertial_kinematics.hpp), the rotation alone.
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  kinematics::for_each_piece(readings, t0, t1, [&](const kinematics::Reading& a, const kinematics::Reading& b, double dt) {
    rotation = rotation * kinematics::exp_so3((0.5 * (a.gyro + b.gyro) - bias) * dt);
  });
  return rotation;
}

bool gyro_stuck(std::span<const ImuSample> readings, double t0, double t1, std::size_t min_readings) {
  const ImuSample* first = nullptr;
  std::size_t count = 0;
  std::array<bool, 3> same{true, true, true};
  for (const ImuSample& r : readings) {
    if (r.t < t0 || r.t > t1 || !r.has_gyro) continue;
    if (first == nullptr) first = &r;
    for (int a = 0; a < 3; ++a) same[static_cast<std::size_t>(a)] = same[static_cast<std::size_t>(a)] && r.angular_rate[a] == first->angular_rate[a];
    ++count;
  }
  return count >= min_readings && (same[0] || same[1] || same[2]);
}

bool GyroBias::still(const Eigen::Vector3d& mean_rate, double t0, double t1) {
  if (!(t1 > t0) || !mean_rate.allFinite()) return false;
  // The mean of white rate noise over T has variance density²/T.
  const double measured = noise_.rate_density * noise_.rate_density / (t1 - t0);
  const double before = learnt_ ? variance_ + noise_.bias_walk * noise_.bias_walk * std::max(t1 - at_, 0.0)
                                : noise_.initial_bias_sigma * noise_.initial_bias_sigma;
  if ((mean_rate - bias_).cwiseAbs().maxCoeff() > 3.0 * std::sqrt(before + measured)) return false;
  const double gain = before / (before + measured);
  bias_ += gain * (mean_rate - bias_);
  variance_ = (1.0 - gain) * before;
  at_ = t1;
  learnt_ = true;
  return true;
}

double GyroBias::sigma(double t) const {
  if (!learnt_) return noise_.initial_bias_sigma;
  return std::sqrt(variance_ + noise_.bias_walk * noise_.bias_walk * std::max(t - at_, 0.0));
}

std::optional<MotionPrior> gyro_aided(const MotionPrior& wheels, const Eigen::Matrix3d& rotation, double dt,
                                      double bias_sigma, const GyroNoise& noise) {
  MotionPrior prior = wheels;
  prior.delta.linear() = rotation;
  const double turn = Eigen::AngleAxisd(rotation).angle();
  // What the gyroscope itself gets wrong (its datasheet's noise, the bias's
  // σ, its scale), and what the prior allows besides: the model error, so
  // that over many scans the map, not the gyroscope's bias, holds the heading.
  const double own = noise.rate_density * noise.rate_density * dt + (bias_sigma * dt) * (bias_sigma * dt) +
                     (noise.scale_error * turn) * (noise.scale_error * turn);
  const double variance = own + noise.model_error_density * noise.model_error_density * dt;
  // Do the gyroscope and the wheels agree, within the wheels' σ (5 % of the
  // turn) and the gyroscope's own? A stuck one reads a corner as straight.
  const Eigen::AngleAxisd apart(wheels.delta.linear().transpose() * rotation);
  const Eigen::Vector3d difference = apart.axis() * apart.angle();
  const Eigen::Matrix3d together = wheels.covariance.block<3, 3>(3, 3) + own * Eigen::Matrix3d::Identity();
  constexpr double kChi2Three999 = 16.27;
  if (!(difference.dot(together.ldlt().solve(difference)) <= kChi2Three999)) return std::nullopt;
  prior.covariance.block<3, 3>(3, 3) = variance * Eigen::Matrix3d::Identity();
  prior.covariance.block<3, 3>(0, 3).setZero();
  prior.covariance.block<3, 3>(3, 0).setZero();
  return prior;
}

}  // namespace adit::slam
