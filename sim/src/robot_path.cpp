#include "adit/sim/robot_path.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "adit/sim/hash_noise.hpp"

namespace adit::sim {
namespace {

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

// Arc length travelled on one leg of `duration` with cruise speed v, sampled at Trajectory::kRate.
std::vector<double> leg_profile(double duration, double v) {
  const auto n = static_cast<std::size_t>(std::llround(duration * Trajectory::kRate));
  std::vector<double> s(n + 1, 0.0);
  const double dt = 1.0 / Trajectory::kRate;
  const auto speed = [&](double t) {
    return v * smoothstep(t / RobotPathOptions::kRamp) * smoothstep((duration - t) / RobotPathOptions::kRamp);
  };
  for (std::size_t i = 1; i <= n; ++i) {
    const double t = static_cast<double>(i) * dt;
    s[i] = s[i - 1] + 0.5 * dt * (speed(t - dt) + speed(t));  // trapezoid rule
  }
  return s;
}

struct RoutePoint {
  Eigen::Vector2d position;
  double heading = 0.0;
};

RoutePoint route_at(const Route& route, double s) {
  const auto n = static_cast<double>(route.points.size());
  double x = s / Route::kStep;
  if (route.closed) {
    x = std::fmod(x, n);
    if (x < 0) x += n;
  } else {
    x = std::clamp(x, 0.0, n - 1.0001);
  }
  const auto i = static_cast<std::size_t>(x);
  const std::size_t j = route.closed ? (i + 1) % route.points.size() : std::min(i + 1, route.points.size() - 1);
  const Eigen::Vector2d& a = route.points[i];
  const Eigen::Vector2d& b = route.points[j];
  // Heading from a wider chord: smooth over the route's 5 cm samples.
  const std::size_t k0 = route.closed ? (i + route.points.size() - 10) % route.points.size() : (i >= 10 ? i - 10 : 0);
  const std::size_t k1 = route.closed ? (i + 10) % route.points.size() : std::min(i + 10, route.points.size() - 1);
  const Eigen::Vector2d d = route.points[k1] - route.points[k0];
  return {a + (b - a) * (x - static_cast<double>(i)), std::atan2(d.y(), d.x())};
}

}  // namespace

double robot_min_duration_s() { return std::numbers::pi / RobotPathOptions::kTurnRate + 4.0 * RobotPathOptions::kRamp; }

Trajectory robot_path(const Scene& scene, const RobotPathOptions& o) {
  const Route& route = scene.route;
  const double length = route.length();
  const double turn = std::numbers::pi / RobotPathOptions::kTurnRate;
  const double cruise_time = o.duration_s - RobotPathOptions::kRamp;  // two half-ramps lose one ramp time
  // Per sample: arc length along the route, and whether driving backwards along it (after the turn).
  std::vector<double> arc;
  std::vector<double> turn_fraction;  // 0 outbound, 1 returning, in between while turning
  if (route.closed && o.speed_mps * cruise_time >= length) {
    const double laps = std::floor(o.speed_mps * cruise_time / length);
    arc = leg_profile(o.duration_s, laps * length / cruise_time);
    turn_fraction.assign(arc.size(), 0.0);
  } else {
    const double leg = (o.duration_s - turn) / 2.0;
    const double longest = route.closed ? length : length - 1.0;
    const double v = std::min(o.speed_mps, longest / (leg - RobotPathOptions::kRamp));
    const std::vector<double> out = leg_profile(leg, v);
    const double far = out.back();
    arc = out;
    turn_fraction.assign(out.size(), 0.0);
    const auto turn_samples = static_cast<std::size_t>(std::llround(turn * Trajectory::kRate));
    for (std::size_t i = 1; i <= turn_samples; ++i) {
      arc.push_back(far);
      turn_fraction.push_back(smoothstep(static_cast<double>(i) / static_cast<double>(turn_samples)));
    }
    for (std::size_t i = 1; i < out.size(); ++i) {
      arc.push_back(far - out[i]);
      turn_fraction.push_back(1.0);
    }
  }
  // Exactly the requested duration: rounding the legs may leave a sample or two; stand still.
  const auto total = static_cast<std::size_t>(std::llround(o.duration_s * Trajectory::kRate)) + 1;
  arc.resize(total, arc.back());
  turn_fraction.resize(total, turn_fraction.back());
  std::vector<BodySample> samples(arc.size());
  for (std::size_t i = 0; i < arc.size(); ++i) {
    const RoutePoint r = route_at(route, arc[i]);
    const Eigen::Vector2d left(-std::sin(r.heading), std::cos(r.heading));
    const Eigen::Vector2d xy = r.position + left * o.lateral_offset_m;
    const double yaw = r.heading + std::numbers::pi * turn_fraction[i];
    // Bumps: the rough floor under the wheels tilts the body (~1 m wavelengths).
    const double travelled = arc[i] + 1000.0 * turn_fraction[i];
    const double deg = std::numbers::pi / 180.0;
    const double roll = o.bump_deg * deg * value_noise3(o.seed ^ 0x526F6C6CULL, travelled / 1.3, 0.5, 0.5);
    const double pitch = o.bump_deg * deg * value_noise3(o.seed ^ 0x50697463ULL, travelled / 0.9, 0.5, 0.5);
    const double z = o.body_height_m + 0.01 * value_noise3(o.seed ^ 0x5AULL, travelled / 0.7, 0.5, 0.5);
    BodySample& b = samples[i];
    b.position = Eigen::Vector3d(xy.x(), xy.y(), z);
    b.orientation = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                    Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  }
  // Wheel inputs: forward speed and yaw rate by central differences.
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const std::size_t a = i > 0 ? i - 1 : i, b = std::min(i + 1, samples.size() - 1);
    if (a == b) continue;
    const double dt = static_cast<double>(b - a) / Trajectory::kRate;
    const Eigen::Vector3d forward = samples[i].orientation * Eigen::Vector3d::UnitX();
    samples[i].speed_mps = (samples[b].position - samples[a].position).dot(forward) / dt;
    const Eigen::Vector3d fa = samples[a].orientation * Eigen::Vector3d::UnitX();
    const Eigen::Vector3d fb = samples[b].orientation * Eigen::Vector3d::UnitX();
    samples[i].yaw_rate_rps = std::remainder(std::atan2(fb.y(), fb.x()) - std::atan2(fa.y(), fa.x()), 2 * std::numbers::pi) / dt;
  }
  return Trajectory(std::move(samples));
}

}  // namespace adit::sim
