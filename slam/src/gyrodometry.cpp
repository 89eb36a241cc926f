#include "adit/slam/gyrodometry.hpp"

#include <algorithm>
#include <cmath>

namespace adit::slam {

std::optional<Eigen::Matrix3d> gyro_rotation(std::span<const ImuSample> readings, double t0, double t1,
                                             const Eigen::Vector3d& bias, double max_gap_s) {
  if (!(t1 > t0) || readings.size() < 2 || readings.front().t > t0 || readings.back().t < t1) return std::nullopt;
  const auto rate_at = [](const ImuSample& a, const ImuSample& b, double t) {
    return Eigen::Vector3d(a.angular_rate + (b.angular_rate - a.angular_rate) * ((t - a.t) / (b.t - a.t)));
  };
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  for (std::size_t i = 0; i + 1 < readings.size(); ++i) {
    const ImuSample& a = readings[i];
    const ImuSample& b = readings[i + 1];
    if (a.t >= t1) break;
    if (b.t <= t0) continue;
    if (!a.has_gyro || !b.has_gyro || !(b.t > a.t) || b.t - a.t > max_gap_s) return std::nullopt;
    const double from = std::max(a.t, t0);
    const double to = std::min(b.t, t1);
    if (!(to > from)) continue;
    const Eigen::Vector3d step = (0.5 * (rate_at(a, b, from) + rate_at(a, b, to)) - bias) * (to - from);
    const double angle = step.norm();
    if (angle > 0.0) rotation = rotation * Eigen::AngleAxisd(angle, step / angle).toRotationMatrix();
  }
  return rotation;
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

MotionPrior gyro_aided(const MotionPrior& wheels, const Eigen::Matrix3d& rotation, double dt, double bias_sigma,
                       const GyroNoise& noise) {
  MotionPrior prior = wheels;
  prior.delta.linear() = rotation;
  const double turn = Eigen::AngleAxisd(rotation).angle();
  const double density2 = noise.rate_density * noise.rate_density + noise.model_error_density * noise.model_error_density;
  const double variance = density2 * dt + (bias_sigma * dt) * (bias_sigma * dt) +
                          (noise.scale_error * turn) * (noise.scale_error * turn);
  prior.covariance.block<3, 3>(3, 3) = variance * Eigen::Matrix3d::Identity();
  prior.covariance.block<3, 3>(0, 3).setZero();
  prior.covariance.block<3, 3>(3, 0).setZero();
  return prior;
}

}  // namespace adit::slam
