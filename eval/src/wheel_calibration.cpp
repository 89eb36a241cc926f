#include "adit/eval/wheel_calibration.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

namespace adit::eval {
namespace {

Eigen::Vector2d position_at(std::span<const PlanarPosition> ref, double t) {
  const auto it = std::lower_bound(ref.begin(), ref.end(), t, [](const PlanarPosition& p, double v) { return p.t < v; });
  if (it == ref.begin()) return {ref.front().x, ref.front().y};
  if (it == ref.end()) return {ref.back().x, ref.back().y};
  const PlanarPosition& b = *it;
  const PlanarPosition& a = *(it - 1);
  const double u = b.t > a.t ? (t - a.t) / (b.t - a.t) : 0.0;
  return {a.x + u * (b.x - a.x), a.y + u * (b.y - a.y)};
}

// Cumulative wheel travel (trapezoid rule) at each sample, interpolated between.
class WheelTravel {
 public:
  // Samples whose time does not increase, or that are not finite, are skipped.
  explicit WheelTravel(std::span<const WheelSpeedSample> w) {
    const WheelSpeedSample* last = nullptr;
    for (const WheelSpeedSample& s : w) {
      if (!std::isfinite(s.t) || !std::isfinite(s.left) || !std::isfinite(s.right)) continue;
      if (last != nullptr && !(s.t > last->t)) continue;
      const double dt = last != nullptr ? s.t - last->t : 0.0;
      t_.push_back(s.t);
      left_.push_back(last != nullptr ? left_.back() + 0.5 * (s.left + last->left) * dt : 0.0);
      right_.push_back(last != nullptr ? right_.back() + 0.5 * (s.right + last->right) * dt : 0.0);
      last = &s;
    }
    if (t_.size() < 2) throw std::invalid_argument("calibration needs at least two wheel samples with increasing times");
  }
  // (left, right) travelled since the first sample, at encoder time t.
  std::pair<double, double> at(double t) const {
    const auto it = std::lower_bound(t_.begin(), t_.end(), t);
    if (it == t_.begin()) return {left_.front(), right_.front()};
    if (it == t_.end()) return {left_.back(), right_.back()};
    const auto i = static_cast<std::size_t>(it - t_.begin());
    const double u = (t - t_[i - 1]) / (t_[i] - t_[i - 1]);
    return {left_[i - 1] + u * (left_[i] - left_[i - 1]), right_[i - 1] + u * (right_[i] - right_[i - 1])};
  }
  const std::vector<double>& times() const { return t_; }

 private:
  std::vector<double> t_, left_, right_;
};

double heading_at(std::span<const PlanarPosition> ref, double t, double span) {
  const Eigen::Vector2d d = position_at(ref, t + 0.5 * span) - position_at(ref, t - 0.5 * span);
  return std::atan2(d.y(), d.x());
}

struct Window {
  double t0 = 0.0;
  double t1 = 0.0;
  double distance = 0.0;  // reference path length
  double dheading = 0.0;  // reference heading change
};

// Parameters in a fixed order: left scale, right scale, track, time offset.
using Params = Eigen::Vector4d;

Eigen::VectorXd residuals(const Params& p, const std::vector<Window>& windows, const WheelTravel& travel,
                          const CalibrationOptions& o) {
  Eigen::VectorXd r(2 * windows.size());
  for (std::size_t k = 0; k < windows.size(); ++k) {
    const auto [l0, r0] = travel.at(windows[k].t0 - p[3]);
    const auto [l1, r1] = travel.at(windows[k].t1 - p[3]);
    const double dl = p[0] * (l1 - l0);
    const double dr = p[1] * (r1 - r0);
    r[static_cast<Eigen::Index>(2 * k)] = (0.5 * (dl + dr) - windows[k].distance) / o.sigma_distance;
    r[static_cast<Eigen::Index>(2 * k + 1)] = slam::wrap_angle((dr - dl) / p[2] - windows[k].dheading) / o.sigma_heading;
  }
  return r;
}

double rms_of(const Eigen::VectorXd& r, std::size_t offset, double sigma) {
  double sum = 0.0;
  std::size_t n = 0;
  for (auto i = static_cast<Eigen::Index>(offset); i < r.size(); i += 2, ++n) sum += r[i] * r[i];
  return n == 0 ? 0.0 : std::sqrt(sum / static_cast<double>(n)) * sigma;
}

}  // namespace

double path_length(std::span<const PlanarPosition> ref, double t0, double t1) {
  double length = 0.0;
  Eigen::Vector2d last = position_at(ref, t0);
  for (const PlanarPosition& p : ref) {
    if (p.t <= t0 || p.t >= t1) continue;
    length += (Eigen::Vector2d(p.x, p.y) - last).norm();
    last = {p.x, p.y};
  }
  return length + (position_at(ref, t1) - last).norm();
}

std::vector<slam::Pose2> dead_reckon(std::span<const WheelSpeedSample> wheels, double left_scale, double right_scale,
                               double effective_track, double time_offset, const slam::Pose2& start, double t0, double t1) {
  const WheelTravel travel(wheels);
  std::vector<double> times{t0};
  for (const double tw : travel.times())
    if (tw + time_offset > t0 && tw + time_offset < t1) times.push_back(tw + time_offset);
  times.push_back(t1);
  std::vector<slam::Pose2> poses{start};
  slam::Pose2 pose = start;
  Eigen::Matrix3d unused = Eigen::Matrix3d::Zero();
  auto previous = travel.at(t0 - time_offset);
  for (std::size_t i = 1; i < times.size(); ++i) {
    const auto now = travel.at(times[i] - time_offset);
    slam::integrate_wheel_travel(pose, unused, left_scale * (now.first - previous.first),
                           right_scale * (now.second - previous.second), effective_track, slam::WheelNoise{});
    poses.push_back(pose);
    previous = now;
  }
  return poses;
}

CalibrationResult calibrate_wheels(std::span<const WheelSpeedSample> wheels, std::span<const PlanarPosition> reference,
                                   const CalibrationOptions& o) {
  if (wheels.size() < 2 || reference.size() < 2) throw std::invalid_argument("calibration needs wheel and reference samples");
  if (!(o.window > 0) || !(o.heading_span > 0) || !(o.sigma_distance > 0) || !(o.sigma_heading > 0) ||
      !(o.max_time_offset >= 0) || !(o.nominal.effective_track() > 0))
    throw std::invalid_argument("calibration options: window, heading span, sigmas and track must be positive");
  const WheelTravel travel(wheels);
  const double margin = o.max_time_offset + o.heading_span;
  const double t_begin = std::max(reference.front().t, wheels.front().t) + margin;
  const double t_end = std::min(reference.back().t, wheels.back().t) - margin;
  std::vector<Window> windows;
  for (double t = t_begin; t + o.window <= t_end; t += o.window) {
    Window w{t, t + o.window, path_length(reference, t, t + o.window), 0.0};
    if (w.distance < o.min_speed * o.window) continue;
    w.dheading = slam::wrap_angle(heading_at(reference, w.t1, o.heading_span) - heading_at(reference, w.t0, o.heading_span));
    windows.push_back(w);
  }
  if (windows.size() < 4) throw std::invalid_argument("too few moving windows where wheels and reference overlap");

  std::vector<int> free{0, 2};
  if (o.separate_scales) free.insert(free.begin() + 1, 1);
  if (o.fit_time_offset) free.push_back(3);
  const auto full = [&](const Eigen::VectorXd& x, Params p) {
    for (std::size_t i = 0; i < free.size(); ++i) p[free[i]] = x[static_cast<Eigen::Index>(i)];
    if (!o.separate_scales) p[1] = p[0];
    p[3] = std::clamp(p[3], -o.max_time_offset, o.max_time_offset);
    return p;
  };
  const Params nominal(o.nominal.left_scale, o.separate_scales ? o.nominal.right_scale : o.nominal.left_scale,
                       o.nominal.effective_track(), 0.0);
  Eigen::VectorXd x(free.size());
  for (std::size_t i = 0; i < free.size(); ++i) x[static_cast<Eigen::Index>(i)] = nominal[free[i]];

  CalibrationResult out;
  out.windows = windows.size();
  const Eigen::VectorXd r_before = residuals(nominal, windows, travel, o);
  out.rms_distance_before = rms_of(r_before, 0, o.sigma_distance);
  out.rms_heading_before = rms_of(r_before, 1, o.sigma_heading);

  // Levenberg-Marquardt with Marquardt's diagonal scaling.
  const std::array<double, 4> step{1e-5, 1e-5, 1e-5, 1e-3};
  const auto jacobian = [&](const Eigen::VectorXd& at) {
    Eigen::MatrixXd j(2 * static_cast<Eigen::Index>(windows.size()), at.size());
    for (Eigen::Index c = 0; c < at.size(); ++c) {
      Eigen::VectorXd hi = at, lo = at;
      const double h = step[static_cast<std::size_t>(free[static_cast<std::size_t>(c)])];
      hi[c] += h;
      lo[c] -= h;
      j.col(c) = (residuals(full(hi, nominal), windows, travel, o) - residuals(full(lo, nominal), windows, travel, o)) / (2 * h);
    }
    return j;
  };
  double lambda = 1e-3;
  Eigen::VectorXd r = residuals(full(x, nominal), windows, travel, o);
  double cost = r.squaredNorm();
  Eigen::MatrixXd j = jacobian(x);
  for (out.iterations = 0; out.iterations < o.max_iterations; ++out.iterations) {
    const Eigen::MatrixXd a = j.transpose() * j;
    const Eigen::VectorXd g = j.transpose() * r;
    Eigen::MatrixXd damped = a;
    damped.diagonal() += lambda * a.diagonal().cwiseMax(1e-12);
    const Eigen::VectorXd delta = damped.ldlt().solve(-g);
    Eigen::VectorXd candidate = x + delta;
    if (o.fit_time_offset) candidate[candidate.size() - 1] = std::clamp(candidate[candidate.size() - 1], -o.max_time_offset, o.max_time_offset);
    const Eigen::VectorXd r_new = residuals(full(candidate, nominal), windows, travel, o);
    const double cost_new = r_new.squaredNorm();
    if (cost_new < cost) {
      const bool small = delta.cwiseAbs().maxCoeff() < 1e-7 || (cost - cost_new) < 1e-10 * cost;
      x = candidate;
      r = r_new;
      cost = cost_new;
      j = jacobian(x);
      lambda = std::max(lambda / 10, 1e-9);
      if (small) {
        out.converged = true;
        break;
      }
    } else {
      lambda *= 10;
      if (lambda > 1e9) {
        out.converged = true;  // no descent direction left: at a minimum
        break;
      }
    }
  }
  const Params p = full(x, nominal);
  out.left_scale = p[0];
  out.right_scale = p[1];
  out.effective_track = p[2];
  out.time_offset = p[3];
  out.rms_distance_after = rms_of(r, 0, o.sigma_distance);
  out.rms_heading_after = rms_of(r, 1, o.sigma_heading);
  // Parameter covariance (J^T J)^-1 scaled by the a-posteriori variance factor.
  const auto m = static_cast<double>(r.size());
  const auto n = static_cast<double>(x.size());
  const Eigen::MatrixXd cov = (j.transpose() * j).inverse() * (cost / std::max(1.0, m - n));
  for (std::size_t i = 0; i < free.size(); ++i)
    out.standard_deviation[free[i]] = std::sqrt(std::max(0.0, cov(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i))));
  if (!o.separate_scales) out.standard_deviation[1] = out.standard_deviation[0];

  // Endpoint error of dead reckoning over the span used, before and after.
  const double t0 = t_begin;
  const double t1 = t_end;
  const Eigen::Vector2d start = position_at(reference, t0);
  const Eigen::Vector2d end = position_at(reference, t1);
  const slam::Pose2 start_pose{start.x(), start.y(), heading_at(reference, t0, o.heading_span)};
  const auto endpoint = [&](const Params& q, double& length) {
    const std::vector<slam::Pose2> poses = dead_reckon(wheels, q[0], q[1], q[2], q[3], start_pose, t0, t1);
    length = 0.0;
    for (std::size_t i = 1; i < poses.size(); ++i)
      length += std::hypot(poses[i].x - poses[i - 1].x, poses[i].y - poses[i - 1].y);
    return std::hypot(poses.back().x - end.x(), poses.back().y - end.y());
  };
  out.endpoint_error_before = endpoint(nominal, out.wheel_length_before);
  out.endpoint_error_after = endpoint(p, out.wheel_length_after);
  out.reference_length = path_length(reference, t0, t1);
  return out;
}

}  // namespace adit::eval
