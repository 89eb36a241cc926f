#include "adit/drivers/lidar/sensor_clock.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace adit::drivers {
namespace {
constexpr std::int64_t kHalfHourUs = 1'800'000'000;

// The multiple of an hour nearest `value`.
std::int64_t nearest_hour(std::int64_t value) {
  const std::int64_t h = TopOfHourClock::kHourNs;
  const std::int64_t floor = (value >= 0 ? value : value - h + 1) / h * h;
  return value - floor >= h / 2 ? floor + h : floor;
}
}  // namespace

std::int64_t TopOfHourClock::resolve(std::uint32_t us_past_hour, std::int64_t reference_ns) {
  const std::int64_t us = us_past_hour;
  if (!anchored_) {
    hour_start_ns_ = nearest_hour(reference_ns - us * 1000);
    anchored_ = true;
    last_us_ = us_past_hour;
  } else if (us < std::int64_t{last_us_} - kHalfHourUs) {
    hour_start_ns_ += kHourNs;  // the top of the hour passed
    ++rollovers_;
    last_us_ = us_past_hour;
  } else if (us > std::int64_t{last_us_} + kHalfHourUs) {
    return hour_start_ns_ - kHourNs + us * 1000;  // a late packet from before the rollover
  } else {
    last_us_ = std::max(last_us_, us_past_hour);
  }
  return hour_start_ns_ + us * 1000;
}

void TopOfHourClock::anchor(std::uint32_t us_past_hour, std::int64_t utc_ns) {
  hour_start_ns_ = nearest_hour(utc_ns - std::int64_t{us_past_hour} * 1000);
  last_us_ = us_past_hour;
  anchored_ = true;
  gps_ = true;
}

ClockOffsetEstimator::ClockOffsetEstimator(std::int64_t window_ns, std::size_t windows, std::int64_t reset_ns)
    : window_ns_(std::max<std::int64_t>(window_ns, 1)),
      capacity_(std::clamp<std::size_t>(windows, 2, kMaxWindows)),
      reset_ns_(reset_ns) {}

void ClockOffsetEstimator::add(std::int64_t sensor_ns, std::int64_t host_ns) {
  const std::int64_t offset = host_ns - sensor_ns;
  const bool stepped = fit_ && std::llabs(offset - fit_->offset_ns) > reset_ns_ &&
                       std::llabs(offset - window_min_.offset_ns) > reset_ns_;
  if (stepped || (window_open_ && sensor_ns < window_start_ns_)) {
    ++resets_;
    count_ = 0;
    head_ = 0;
    window_open_ = false;
    fit_.reset();
  }
  if (!window_open_) {
    window_open_ = true;
    window_start_ns_ = sensor_ns;
    window_min_ = {sensor_ns, offset};
  } else if (offset < window_min_.offset_ns) {
    window_min_ = {sensor_ns, offset};
  }
  last_sensor_ns_ = sensor_ns;
  if (sensor_ns - window_start_ns_ >= window_ns_) {
    close_window();
  } else if (count_ == 0) {
    // Before the first full window, the running minimum is the best we have.
    fit_ = ClockEstimate{window_min_.offset_ns, 0.0, sensor_ns, 0};
  }
}

void ClockOffsetEstimator::close_window() {
  minima_[head_] = window_min_;
  head_ = (head_ + 1) % capacity_;
  count_ = std::min(count_ + 1, capacity_);
  window_open_ = false;
  refit();
}

void ClockOffsetEstimator::refit() {
  // Least squares offset = a + b·(t − t0), in doubles relative to the newest minimum.
  const Minimum& newest = minima_[(head_ + capacity_ - 1) % capacity_];
  double st = 0, so = 0, stt = 0, sto = 0;
  for (std::size_t i = 0; i < count_; ++i) {
    const double t = static_cast<double>(minima_[i].sensor_ns - newest.sensor_ns) * 1e-9;
    const double o = static_cast<double>(minima_[i].offset_ns - newest.offset_ns);
    st += t;
    so += o;
    stt += t * t;
    sto += t * o;
  }
  const double n = static_cast<double>(count_);
  const double denominator = n * stt - st * st;
  const double slope = count_ >= 2 && denominator > 1e-12 ? (n * sto - st * so) / denominator : 0.0;  // ns per s
  const double intercept = (so - slope * st) / n;
  ClockEstimate e;
  e.drift_ppm = slope * 1e-3;
  e.at_sensor_ns = last_sensor_ns_;
  const double since_newest_s = static_cast<double>(last_sensor_ns_ - newest.sensor_ns) * 1e-9;
  e.offset_ns = newest.offset_ns + static_cast<std::int64_t>(std::llround(intercept + slope * since_newest_s));
  e.windows = static_cast<std::uint32_t>(count_);
  fit_ = e;
}

std::optional<ClockEstimate> ClockOffsetEstimator::estimate() const { return fit_; }

std::int64_t ClockOffsetEstimator::to_host(std::int64_t sensor_ns) const {
  if (!fit_) return sensor_ns;
  const double since_s = static_cast<double>(sensor_ns - fit_->at_sensor_ns) * 1e-9;
  return sensor_ns + fit_->offset_ns + static_cast<std::int64_t>(std::llround(fit_->drift_ppm * 1e3 * since_s));
}

}  // namespace adit::drivers
