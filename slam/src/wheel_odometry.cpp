#include "adit/slam/wheel_odometry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>

namespace adit::slam {

std::int64_t counter_delta(std::uint64_t previous, std::uint64_t current, unsigned bits) {
  bits = std::clamp(bits, 1U, 64U);
  const std::uint64_t diff = current - previous;  // modulo 2^64
  if (bits == 64) return static_cast<std::int64_t>(diff);
  const std::uint64_t mask = (std::uint64_t{1} << bits) - 1;
  const std::uint64_t d = diff & mask;
  const std::uint64_t half = std::uint64_t{1} << (bits - 1);
  return d >= half ? static_cast<std::int64_t>(d) - static_cast<std::int64_t>(mask) - 1 : static_cast<std::int64_t>(d);
}

void integrate_wheel_travel(Pose2& pose, Eigen::Matrix3d& covariance, double ds_left, double ds_right,
                            double effective_track, const WheelNoise& noise) {
  const double b = effective_track;
  const double ds = 0.5 * (ds_left + ds_right);
  const double dtheta = (ds_right - ds_left) / b;
  const double mid = pose.theta + 0.5 * dtheta;
  const double c = std::cos(mid);
  const double s = std::sin(mid);

  // Siegwart et al. eq. 5.9-5.11: F_p with respect to the pose, F_d with
  // respect to (ds_right, ds_left).
  Eigen::Matrix3d fp = Eigen::Matrix3d::Identity();
  fp(0, 2) = -ds * s;
  fp(1, 2) = ds * c;
  Eigen::Matrix<double, 3, 2> fd;
  fd << 0.5 * c - ds / (2 * b) * s, 0.5 * c + ds / (2 * b) * s,  //
      0.5 * s + ds / (2 * b) * c, 0.5 * s - ds / (2 * b) * c,      //
      1.0 / b, -1.0 / b;
  const Eigen::Vector2d wheel_variance(noise.k_right * std::abs(ds_right), noise.k_left * std::abs(ds_left));
  covariance = fp * covariance * fp.transpose() + fd * wheel_variance.asDiagonal() * fd.transpose();
  covariance(2, 2) += noise.k_turn * std::abs(dtheta);

  pose.x += ds * c;
  pose.y += ds * s;
  pose.theta = wrap_angle(pose.theta + dtheta);
}

WheelOdometry::WheelOdometry(const WheelGeometry& geometry, const WheelNoise& noise, const WheelLimits& limits)
    : geometry_(geometry), noise_(noise), limits_(limits) {}

void WheelOdometry::reset(const Pose2& pose) {
  pose_ = pose;
  covariance_.setZero();
  distance_ = 0.0;
  have_previous_ = false;
  have_counts_ = false;
  rejected_in_a_row_ = 0;
  slip_since_ = {kNotSlipping, kNotSlipping};
  slip_ended_ = {kNotSlipping, kNotSlipping};
  speeds_known_ = false;
  earlier_known_ = false;
}

WheelStep WheelOdometry::add_speeds(double t, double v_left, double v_right) { return step(t, v_left, v_right, false); }

WheelStep WheelOdometry::add_wheel_rates(double t, double w_left, double w_right) {
  return step(t, w_left * geometry_.left_radius, w_right * geometry_.right_radius, false);
}

WheelStep WheelOdometry::add_counts(double t, std::uint64_t left, std::uint64_t right) {
  if (!have_counts_ || !have_previous_) {
    left_count_ = left;
    right_count_ = right;
    have_counts_ = true;
    return step(t, 0.0, 0.0, true);
  }
  const double dt = t - t_previous_;
  if (!(dt > 0.0)) return step(t, 0.0, 0.0, true);  // reports time_backwards
  const std::int64_t dl = counter_delta(left_count_, left, geometry_.counter_bits);
  const std::int64_t dr = counter_delta(right_count_, right, geometry_.counter_bits);
  const double per_count = 2.0 * std::numbers::pi / geometry_.counts_per_revolution;
  const WheelStep result =
      step(t, static_cast<double>(dl) * per_count * geometry_.left_radius / dt,
           static_cast<double>(dr) * per_count * geometry_.right_radius / dt, true);
  // An impossible reading keeps the old baseline, so the next good reading
  // covers the whole interval exactly (encoder counts are absolute). A
  // slipping wheel's counts are spent: step() integrated its trusted speed.
  if (result != WheelStep::impossible && result != WheelStep::time_backwards) {
    if ((dl > 0 && left < left_count_) || (dl < 0 && left > left_count_)) ++stats_.counter_wraps;
    if ((dr > 0 && right < right_count_) || (dr < 0 && right > right_count_)) ++stats_.counter_wraps;
    left_count_ = left;
    right_count_ = right;
  }
  return result;
}

WheelOdometry::TractionCheck WheelOdometry::check_traction(double t, double dt, const std::array<double, 2>& measured,
                                                          bool from_counts) {
  // Slip, wheel by wheel: a speed change beyond what the wheel's traction
  // allows over the interval, plus the measurement's noise. A speed from
  // counts is uncertain by count_noise counts and by its speed times the
  // timestamp jitter, both over the interval. A speed from counts is the
  // mean over its interval, so a slip that starts within an interval shows
  // half in one reading and half in the next, each below the bound, but not
  // both together: counts are also judged against the trusted speed before
  // the last one. (Reported speeds are samples: a step shows at once, and
  // their noise, up to 1 m/s on a car's ABS sensors, does not shrink over two
  // readings.)
  const std::array<double, 2> trusted{v_left_previous_, v_right_previous_};
  const std::array<double, 2> radius{geometry_.left_radius, geometry_.right_radius};
  const double per_count = 2.0 * std::numbers::pi / geometry_.counts_per_revolution;
  TractionCheck result{measured, trusted};
  std::array<double, 2> bound{};
  std::array<bool, 2> jump{};  // a new slip: beyond the bound from the last trusted speed ...
  std::array<bool, 2> ramp{};  // ... or, counts, from the one before
  for (std::size_t i = 0; i < 2; ++i) {
    const double noise =
        from_counts ? (limits_.count_noise * per_count * radius[i] + std::abs(trusted[i]) * limits_.timestamp_jitter) / dt
                    : limits_.speed_noise;
    bound[i] = limits_.max_acceleration * std::max(dt, limits_.min_interval) + noise;
    if (!speeds_known_ || !std::isnan(slip_since_[i])) continue;
    jump[i] = std::abs(measured[i] - trusted[i]) > bound[i];
    ramp[i] = from_counts && earlier_known_ &&
              std::abs(measured[i] - earlier_speed_[i]) >
                  limits_.max_acceleration * std::max(t - earlier_t_, limits_.min_interval) + noise;
  }
  const std::array<bool, 2> held_before{!std::isnan(slip_since_[0]), !std::isnan(slip_since_[1])};
  for (std::size_t i = 0; i < 2; ++i) {
    const std::size_t other = 1 - i;
    const bool onset = jump[i] || ramp[i];
    if (!onset && !held_before[i]) continue;
    const bool other_trusted = !held_before[other] && !jump[other] && !ramp[other];
    // A slip whose excess fell under the bound (a spin while the vehicle
    // slows) looked over before it was: the speeds since are the spin's. A
    // change soon after is judged by that slip's reference, not by them: back
    // to it, the slip has ended; away from it, the slip goes on.
    const bool resumed = onset && t - slip_ended_[i] <= limits_.max_slip_duration;
    if (onset && !resumed) {
      // The speeds from before the slip began, and what they said of the turn.
      const std::array<double, 2>& pre = jump[i] ? trusted : earlier_speed_;
      slip_since_[i] = jump[i] ? t_previous_ : earlier_t_;
      slip_offset_[i] = pre[i] - pre[other];
      slip_speed_[i] = pre[i];
      ++stats_.slip_episodes;
    }
    // What the wheel would read with traction: the other wheel's speed with
    // the turn rate from before the slip (the vehicle accelerates, the spin
    // does not steer it), or, if the other wheel is not trusted either, this
    // wheel's speed from before the slip.
    const double reference = other_trusted ? measured[other] + slip_offset_[i] : slip_speed_[i];
    if ((!onset || resumed) && std::abs(measured[i] - reference) <= bound[i]) {
      slip_since_[i] = kNotSlipping;  // grips again
      slip_ended_[i] = t;
      continue;
    }
    if (resumed) {  // the same slip, held again
      slip_since_[i] = t_previous_;
      slip_ended_[i] = kNotSlipping;
    }
    if (t - slip_since_[i] > limits_.max_slip_duration) {  // held too long: a real change of speed
      slip_since_[i] = kNotSlipping;
      result.accepted_after_slip = true;
      result.earlier[i] = measured[i];  // the slip's history is no reference for what follows
      continue;
    }
    result.speeds[i] = reference;
    result.slipping = true;
  }
  return result;
}

WheelStep WheelOdometry::step(double t, double v_left, double v_right, bool from_counts) {
  const auto baseline = [&](double vl, double vr) {
    t_previous_ = t;
    v_left_previous_ = vl;
    v_right_previous_ = vr;
    rejected_in_a_row_ = 0;
    have_previous_ = true;
  };
  // A new baseline with no slip and no earlier speeds: `known` says whether
  // its speeds are measured (one reading of counts has none yet).
  const auto restart = [&](double vl, double vr, bool known) {
    baseline(vl, vr);
    slip_since_ = {kNotSlipping, kNotSlipping};
    slip_ended_ = {kNotSlipping, kNotSlipping};
    speeds_known_ = known;
    earlier_known_ = false;
  };
  const bool plausible = std::isfinite(v_left) && std::isfinite(v_right) && std::abs(v_left) <= limits_.max_speed &&
                         std::abs(v_right) <= limits_.max_speed;
  if (!std::isfinite(t)) {
    ++stats_.time_backwards;
    return WheelStep::time_backwards;
  }
  if (!have_previous_) {
    restart(plausible ? v_left : 0.0, plausible ? v_right : 0.0, plausible && !from_counts);
    return WheelStep::first;
  }
  const double dt = t - t_previous_;
  if (!(dt > 0.0)) {
    ++stats_.time_backwards;
    return WheelStep::time_backwards;
  }
  if (dt > limits_.max_gap) {
    ++stats_.gaps;
    restart(plausible ? v_left : 0.0, plausible ? v_right : 0.0, plausible && !from_counts);
    return WheelStep::gap;
  }
  if (!plausible) {
    ++stats_.impossible;
    if (++rejected_in_a_row_ > limits_.max_rejected) {
      ++stats_.rebaselined;
      restart(0.0, 0.0, false);
      return WheelStep::rebaselined;
    }
    if (from_counts) return WheelStep::impossible;  // baseline kept; the next good reading covers this interval
    // Speeds: hold the last trusted speeds over this interval.
    const double hl = v_left_previous_ * dt * geometry_.left_scale;
    const double hr = v_right_previous_ * dt * geometry_.right_scale;
    integrate_wheel_travel(pose_, covariance_, hl, hr, geometry_.effective_track(), noise_);
    distance_ += std::abs(0.5 * (hl + hr));
    t_previous_ = t;
    return WheelStep::impossible;
  }

  const std::array<double, 2> trusted{v_left_previous_, v_right_previous_};
  const TractionCheck traction = check_traction(t, dt, {v_left, v_right}, from_counts);
  const std::array<double, 2>& used = traction.speeds;
  // Counts give the exact travel over the interval; speeds are sampled, so
  // the trapezoid rule integrates them.
  const double vl = from_counts ? used[0] : 0.5 * (used[0] + trusted[0]);
  const double vr = from_counts ? used[1] : 0.5 * (used[1] + trusted[1]);
  const double dl = vl * dt * geometry_.left_scale;
  const double dr = vr * dt * geometry_.right_scale;
  integrate_wheel_travel(pose_, covariance_, dl, dr, geometry_.effective_track(), noise_);
  distance_ += std::abs(0.5 * (dl + dr));
  earlier_speed_ = traction.earlier;
  earlier_t_ = t_previous_;
  earlier_known_ = speeds_known_;
  baseline(used[0], used[1]);
  speeds_known_ = true;
  if (traction.slipping) {
    ++stats_.slips;
    return WheelStep::slip;
  }
  if (traction.accepted_after_slip) {
    ++stats_.rebaselined;
    return WheelStep::rebaselined;
  }
  ++stats_.integrated;
  return WheelStep::integrated;
}

}  // namespace adit::slam
