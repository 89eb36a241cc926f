#include "adit/slam/motion_history.hpp"

#include <cmath>

#include "adit/slam/wheel_prior.hpp"

namespace adit::slam {

bool WheelHistory::interpolate(double t, Pose2& pose, double& distance) const {
  const TimedRing<WheelSample>& at = samples_;
  const std::size_t size = at.size();
  if (size < 2 || t < at[0].t || t > at.back().t) return false;
  // Binary search over the ring for the first sample at or after t.
  std::size_t lo = 1;
  std::size_t hi = size - 1;
  while (lo < hi) {
    const std::size_t mid = (lo + hi) / 2;
    if (at[mid].t < t) lo = mid + 1;
    else hi = mid;
  }
  const WheelSample& a = at[lo - 1];
  const WheelSample& b = at[lo];
  if (b.after_gap && t < b.t) return false;  // inside a silence: the wheels do not know
  const double u = std::clamp((t - a.t) / (b.t - a.t), 0.0, 1.0);
  pose = {a.pose.x + u * (b.pose.x - a.pose.x), a.pose.y + u * (b.pose.y - a.pose.y),
          a.pose.theta + u * wrap_angle(b.pose.theta - a.pose.theta)};
  distance = a.distance + u * (b.distance - a.distance);
  return true;
}

std::optional<MotionPrior> WheelHistory::prior(double t0, double t1) const {
  Pose2 p0;
  Pose2 p1;
  double d0 = 0.0;
  double d1 = 0.0;
  if (!(t1 > t0) || !interpolate(t0, p0, d0) || !interpolate(t1, p1, d1)) return std::nullopt;
  // Newest first: the scans ask about the last few samples.
  for (std::size_t i = samples_.size(); i-- > 0 && samples_[i].t > t0;)
    if (samples_[i].after_gap && samples_[i].t <= t1) return std::nullopt;  // the wheels were silent in between
  if (held(t0, t1)) return std::nullopt;
  return wheel_motion_prior(p0, p1, d1 - d0);
}

bool WheelHistory::held(double t0, double t1) const {
  // Sample i covers (t[i-1], t[i]]: those after t0 up to the first at or after t1.
  for (std::size_t i = samples_.size(); i-- > 0 && samples_[i].t > t0;) {
    if (i > 0 && samples_[i - 1].t >= t1) continue;  // wholly after t1
    if (samples_[i].held) return true;
  }
  return false;
}

std::optional<Eigen::Vector3d> WheelHistory::acceleration(double t0, double t1, double half_window) const {
  if (!(t1 > t0) || !(half_window > 0.0)) return std::nullopt;
  // Forward speed at t: the displacement over [t − h, t + h] along the heading at t.
  const auto speed = [&](double t, double& v, double& heading) {
    Pose2 a, b, mid;
    double d = 0.0;
    if (!interpolate(t - half_window, a, d) || !interpolate(t + half_window, b, d) || !interpolate(t, mid, d)) return false;
    v = ((b.x - a.x) * std::cos(mid.theta) + (b.y - a.y) * std::sin(mid.theta)) / (2.0 * half_window);
    heading = mid.theta;
    return true;
  };
  double v0 = 0.0, v1 = 0.0, h0 = 0.0, h1 = 0.0;
  if (!speed(t0, v0, h0) || !speed(t1, v1, h1) || held(t0 - half_window, t1 + half_window)) return std::nullopt;
  const double dt = t1 - t0;
  const double omega = wrap_angle(h1 - h0) / dt;
  return Eigen::Vector3d((v1 - v0) / dt, omega * 0.5 * (v0 + v1), 0.0);
}

void ImuHistory::copy_covering(double t0, double t1, std::vector<ImuSample>& out) const {
  out.clear();
  const TimedRing<ImuSample>& at = samples_;
  if (at.size() == 0) return;
  std::size_t i = at.size() - 1;  // the last reading at or before t0 (newest first: the wanted ones are recent)
  while (i > 0 && at[i].t > t0) --i;
  for (; i < at.size(); ++i) {
    out.push_back(at[i]);
    if (at[i].t >= t1) break;
  }
}

std::optional<Eigen::Vector3d> ImuHistory::mean(double t0, double t1, std::size_t min_samples) const {
  // The time average over [t0, t1] of the readings joined by straight lines
  // (trapezoids; the ends interpolated): a plain mean of the readings inside
  // would stand for an interval shifted by up to one reading period, and
  // while the robot speeds up at 4 m/s³ a 5 ms shift is 0.02 m/s² (0.1°).
  const TimedRing<ImuSample>& at = samples_;
  const std::size_t size = at.size();
  if (!(t1 > t0) || size < 2 || at[0].t > t0 || at.back().t < t1) return std::nullopt;
  // The last reading at or before t0 (newest first: the wanted ones are the last few).
  std::size_t i = size - 1;
  while (i > 0 && at[i].t > t0) --i;
  const auto value = [&](std::size_t k, double t) {
    const ImuSample& a = at[k];
    const ImuSample& b = at[k + 1];
    return Eigen::Vector3d(a.specific_force + (b.specific_force - a.specific_force) * ((t - a.t) / (b.t - a.t)));
  };
  Eigen::Vector3d integral = Eigen::Vector3d::Zero();
  std::size_t inside = 0;
  for (; i + 1 < size && at[i].t < t1; ++i) {
    const double from = std::max(at[i].t, t0);
    const double to = std::min(at[i + 1].t, t1);
    if (to > from) integral += 0.5 * (value(i, from) + value(i, to)) * (to - from);
    if (at[i + 1].t <= t1) ++inside;
  }
  if (inside < min_samples) return std::nullopt;
  return integral / (t1 - t0);
}

}  // namespace adit::slam
