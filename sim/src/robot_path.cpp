#include "adit/sim/robot_path.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "adit/sim/hash_noise.hpp"
#include "adit/sim/route_schedule.hpp"

namespace adit::sim {
namespace {
ScheduleOptions schedule_options(const RobotPathOptions& o) {
  ScheduleOptions s;
  s.duration_s = o.duration_s;
  s.speed_mps = o.speed_mps;
  s.turn_rate_rps = RobotPathOptions::kTurnRate;
  s.ramp_s = RobotPathOptions::kRamp;
  s.hold_start_s = RobotPathOptions::kHoldStart;
  return s;
}
// Where the body is at arc length s along the route, and where it points:
// the route averaged over a metre of it (a box of ±0.5 m), and the direction
// of that average's derivative, the chord (P(s + h) - P(s - h)) / 2h. Wheels
// roll, they do not slide: the body points exactly where its position runs,
// and turns as smoothly as a metre-long chord of the route does (decision 078).
// The average is a trapezoid sum at half the route's sample spacing (the
// route is linear between samples: what is left is the corners at its samples).
struct PathPoint {
  Eigen::Vector2d position;
  double heading = 0.0;
};
PathPoint smoothed_route_at(const Route& route, double s, double fallback_heading) {
  constexpr double kHalfWindow = 0.5;  // m, route_at's own heading chord
  const auto n = static_cast<int>(std::ceil(4.0 * kHalfWindow / route.step));
  const double step = 2.0 * kHalfWindow / n;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int k = 0; k <= n; ++k)
    sum += (k == 0 || k == n ? 0.5 : 1.0) * route_at(route, s - kHalfWindow + k * step).position;
  const Eigen::Vector2d chord = route_at(route, s + kHalfWindow).position - route_at(route, s - kHalfWindow).position;
  return {sum / n, chord.squaredNorm() > 0.0 ? std::atan2(chord.y(), chord.x()) : fallback_heading};
}

}  // namespace

double robot_min_duration_s() { return min_schedule_duration_s(schedule_options(RobotPathOptions{})); }

BodyTrack robot_path(const Scene& scene, const RobotPathOptions& o) {
  const Route& route = scene.route;
  const RouteSchedule schedule = route_schedule(route, schedule_options(o));
  const std::vector<double>& arc = schedule.arc;
  const std::vector<double>& turn_fraction = schedule.turn_fraction;
  std::vector<BodySample> samples(arc.size());
  double travelled = 0.0;  // by the wheels so far (an odometer)
  for (std::size_t i = 0; i < arc.size(); ++i) {
    const PathPoint r = smoothed_route_at(route, arc[i], route_at(route, arc[i]).heading);
    const Eigen::Vector2d left(-std::sin(r.heading), std::cos(r.heading));
    const Eigen::Vector2d xy = r.position + left * o.lateral_offset_m;
    const double yaw = r.heading + std::numbers::pi * turn_fraction[i];
    // Bumps: the rough floor under the wheels tilts the body (~1 m wavelengths
    // of the distance the wheels have rolled). Turning on the spot, each wheel
    // rolls half the track per radian, so the tilt changes as slowly as the
    // wheels move. (It was the route distance plus 1000 m per turn, which
    // shook the body by up to ±1° some 200 times a second while it turned on
    // the spot: docs/decisions/016-sim-bumps-follow-odometer.md.)
    if (i > 0)
      travelled += std::abs(arc[i] - arc[i - 1]) +
                   0.5 * o.track_m * std::numbers::pi * std::abs(turn_fraction[i] - turn_fraction[i - 1]);
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
    const double dt = static_cast<double>(b - a) / BodyTrack::kRate;
    const Eigen::Vector3d forward = samples[i].orientation * Eigen::Vector3d::UnitX();
    samples[i].speed_mps = (samples[b].position - samples[a].position).dot(forward) / dt;
    const Eigen::Vector3d fa = samples[a].orientation * Eigen::Vector3d::UnitX();
    const Eigen::Vector3d fb = samples[b].orientation * Eigen::Vector3d::UnitX();
    samples[i].yaw_rate_rps = std::remainder(std::atan2(fb.y(), fb.x()) - std::atan2(fa.y(), fa.x()), 2 * std::numbers::pi) / dt;
  }
  return BodyTrack(std::move(samples));
}

}  // namespace adit::sim
