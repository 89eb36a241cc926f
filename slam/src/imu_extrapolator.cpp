#include "adit/slam/imu_extrapolator.hpp"

#include <algorithm>

#include "inertial_kinematics.hpp"

namespace adit::slam {

ImuExtrapolator::ImuExtrapolator(const ImuExtrapolatorConfig& config)
    : config_(config), ring_(std::max<std::size_t>(config.capacity, 2)) {}

void ImuExtrapolator::step(const ImuSample& from, const ImuSample& to) {
  const double dt = to.t - current_.t;
  if (dt <= 0.0) return;  // the anchor is at or after this reading
  // The readings at current_'s time (between `from` and `to`, linear) and at `to`'s.
  const double span = to.t - from.t;
  const double s = span > 0.0 ? std::clamp((current_.t - from.t) / span, 0.0, 1.0) : 1.0;
  const kinematics::Reading a{from.angular_rate + s * (to.angular_rate - from.angular_rate),
                              from.specific_force + s * (to.specific_force - from.specific_force)};
  const kinematics::Reading b{to.angular_rate, to.specific_force};
  const Eigen::Matrix3d R = current_.pose.linear();
  const auto [w, f] = kinematics::integrate(current_, a, b, dt, config_.inertial.imu_position);
  kinematics::propagate_covariance(covariance_, R, w, f, dt, config_.inertial);
  current_.t = to.t;
}

void ImuExtrapolator::anchor(const InertialState& state, const Matrix18d& covariance) {
  anchor_t_ = state.t;
  current_ = state;
  covariance_ = covariance;
  // Readings already past the horizon (a replayed log read far ahead): none
  // of them, nor any later one, gives a pose from this anchor.
  current_valid_ = count_ == 0 || kept(count_ - 1).t - state.t <= config_.max_horizon_s;
  // Again through the readings since the anchor, each from the one before
  // it (the first kept one from itself, held back to the anchor).
  for (std::size_t i = 0; i < count_ && current_valid_; ++i) {
    const ImuSample& to = kept(i);
    if (to.t <= state.t) continue;
    const ImuSample& from = i > 0 ? kept(i - 1) : to;
    const double gap = i > 0 ? to.t - from.t : to.t - state.t;
    if (gap > config_.inertial.max_sample_gap_s) current_valid_ = false;
    else step(from, to);
  }
}

std::optional<InertialState> ImuExtrapolator::add(const ImuSample& reading) {
  if (count_ > 0 && !(reading.t > kept(count_ - 1).t)) return std::nullopt;  // out of order: not kept
  const ImuSample* previous = count_ > 0 ? &kept(count_ - 1) : nullptr;
  const bool gap = previous == nullptr || reading.t - previous->t > config_.inertial.max_sample_gap_s;
  if (anchor_t_ && current_valid_) {
    if (gap && reading.t - current_.t > config_.inertial.max_sample_gap_s) current_valid_ = false;
    else if (previous != nullptr && !gap) step(*previous, reading);
    else step(reading, reading);  // the anchor's time is within a gap's reach of this first reading
  }
  // Kept (the oldest overwritten once full) after stepping: `previous` points into the ring.
  if (count_ < ring_.size()) {
    ring_[(head_ + count_) % ring_.size()] = reading;
    ++count_;
  } else {
    ring_[head_] = reading;
    head_ = (head_ + 1) % ring_.size();
  }
  if (!anchor_t_ || !current_valid_ || reading.t - *anchor_t_ > config_.max_horizon_s) return std::nullopt;
  return current_;
}

Matrix6d ImuExtrapolator::pose_covariance() const {
  return kinematics::body_pose_covariance(covariance_, current_.pose.linear());
}

}  // namespace adit::slam
