#include "adit/sim/route_schedule.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "adit/sim/body_track.hpp"

namespace adit::sim {
namespace {

// Arc length travelled on one leg of `duration` with cruise speed v, sampled at BodyTrack::kRate.
std::vector<double> leg_profile(double duration, double v, double ramp) {
  const auto n = static_cast<std::size_t>(std::llround(duration * BodyTrack::kRate));
  std::vector<double> s(n + 1, 0.0);
  const double dt = 1.0 / BodyTrack::kRate;
  const auto speed = [&](double t) { return v * smoothstep(t / ramp) * smoothstep((duration - t) / ramp); };
  for (std::size_t i = 1; i <= n; ++i) {
    const double t = static_cast<double>(i) * dt;
    s[i] = s[i - 1] + 0.5 * dt * (speed(t - dt) + speed(t));  // trapezoid rule
  }
  return s;
}

}  // namespace

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

double min_schedule_duration_s(const ScheduleOptions& o) {
  return std::numbers::pi / o.turn_rate_rps + 4.0 * o.ramp_s + o.hold_start_s + o.hold_end_s;
}

RouteSchedule route_schedule(const Route& route, const ScheduleOptions& o) {
  const double length = route.length();
  const double moving = o.duration_s - o.hold_start_s - o.hold_end_s;
  const double turn = std::numbers::pi / o.turn_rate_rps;
  const double cruise_time = moving - o.ramp_s;  // two half-ramps lose one ramp time
  RouteSchedule r;
  const auto hold = [&](double seconds, double arc, double turned) {
    const auto n = static_cast<std::size_t>(std::llround(seconds * BodyTrack::kRate));
    r.arc.insert(r.arc.end(), n, arc);
    r.turn_fraction.insert(r.turn_fraction.end(), n, turned);
  };
  hold(o.hold_start_s, 0.0, 0.0);
  if (route.closed && o.speed_mps * cruise_time >= length) {
    const double laps = std::floor(o.speed_mps * cruise_time / length);
    const std::vector<double> s = leg_profile(moving, laps * length / cruise_time, o.ramp_s);
    r.arc.insert(r.arc.end(), s.begin(), s.end());
    r.turn_fraction.insert(r.turn_fraction.end(), s.size(), 0.0);
  } else {
    const double leg = (moving - turn) / 2.0;
    const double longest = route.closed ? length : length - 1.0;
    const double v = std::min(o.speed_mps, longest / (leg - o.ramp_s));
    const std::vector<double> out = leg_profile(leg, v, o.ramp_s);
    const double far = out.back();
    r.arc.insert(r.arc.end(), out.begin(), out.end());
    r.turn_fraction.insert(r.turn_fraction.end(), out.size(), 0.0);
    const auto turn_samples = static_cast<std::size_t>(std::llround(turn * BodyTrack::kRate));
    for (std::size_t i = 1; i <= turn_samples; ++i) {
      r.arc.push_back(far);
      r.turn_fraction.push_back(smoothstep(static_cast<double>(i) / static_cast<double>(turn_samples)));
    }
    for (std::size_t i = 1; i < out.size(); ++i) {
      r.arc.push_back(far - out[i]);
      r.turn_fraction.push_back(1.0);
    }
  }
  // Exactly the requested duration: rounding may leave a sample or two; stand still.
  const auto total = static_cast<std::size_t>(std::llround(o.duration_s * BodyTrack::kRate)) + 1;
  r.arc.resize(total, r.arc.back());
  r.turn_fraction.resize(total, r.turn_fraction.back());
  return r;
}

RoutePoint route_at(const Route& route, double s) {
  const auto n = static_cast<double>(route.points.size());
  double x = s / route.step;
  if (route.closed) {
    x = std::fmod(x, n);
    if (x < 0) x += n;
    if (x >= n) x = 0.0;  // a negative x within rounding of 0 comes back as n: the first point, not one past the last
  } else {
    x = std::clamp(x, 0.0, n - 1.0001);
  }
  const auto i = static_cast<std::size_t>(x);
  const std::size_t m = route.points.size();
  const std::size_t j = route.closed ? (i + 1) % m : std::min(i + 1, m - 1);
  const Eigen::Vector2d& a = route.points[i];
  const Eigen::Vector2d& b = route.points[j];
  // Heading from a wider chord (smooth over the route's 5 cm samples), blended
  // between neighbouring samples so that it turns continuously.
  const auto chord_heading = [&](std::size_t k) {
    const std::size_t k0 = route.closed ? (k + m - 10) % m : (k >= 10 ? k - 10 : 0);
    const std::size_t k1 = route.closed ? (k + 10) % m : std::min(k + 10, m - 1);
    const Eigen::Vector2d d = route.points[k1] - route.points[k0];
    return std::atan2(d.y(), d.x());
  };
  const double f = x - static_cast<double>(i);
  const double h0 = chord_heading(i);
  const double h1 = chord_heading(j);
  return {a + (b - a) * f, h0 + f * std::remainder(h1 - h0, 2.0 * std::numbers::pi)};
}

}  // namespace adit::sim
