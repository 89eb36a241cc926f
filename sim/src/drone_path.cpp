#include "adit/sim/drone_path.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "adit/sim/hash_noise.hpp"
#include "adit/sim/route_schedule.hpp"

namespace adit::sim {
namespace {

constexpr double kGravity = 9.81;
constexpr double kYawSweep = 25.0 * std::numbers::pi / 180.0;
constexpr double kYawPeriod = 8.0;  // s: sweep rate 2π·25°/8 s ≈ 20°/s
constexpr double kYawRate = 0.95 * DronePathOptions::kMaxYawRate;

ScheduleOptions schedule_options(const DronePathOptions& o) {
  ScheduleOptions s;
  s.duration_s = o.duration_s;
  s.speed_mps = o.speed_mps;
  s.turn_rate_rps = DronePathOptions::kTurnRate;
  s.ramp_s = 1.5;
  s.hold_start_s = o.ground_s + DronePathOptions::kClimb + DronePathOptions::kHover;
  s.hold_end_s = DronePathOptions::kHover;
  return s;
}

}  // namespace

double drone_min_duration_s(const DronePathOptions& options) {
  return min_schedule_duration_s(schedule_options(options));
}

BodyTrack drone_path(const Scene& scene, const DronePathOptions& o) {
  const Route& route = scene.route;
  const RouteSchedule schedule = route_schedule(route, schedule_options(o));
  const std::size_t n = schedule.arc.size();
  const double dt = 1.0 / BodyTrack::kRate;
  // Position and yaw first; the tilt needs their accelerations.
  std::vector<Eigen::Vector3d> position(n);
  std::vector<double> yaw(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * dt;
    const RoutePoint r = route_at(route, schedule.arc[i]);
    const Eigen::Vector2d left(-std::sin(r.heading), std::cos(r.heading));
    const Eigen::Vector2d xy = r.position + left * o.lateral_offset_m;
    // On the floor at 0.3 m (its legs), climb, then rise and sink ±0.5 m with
    // the distance flown.
    const double climb = smoothstep((t - o.ground_s) / DronePathOptions::kClimb);
    const double cruise = o.altitude_m + 0.5 * std::sin(2.0 * std::numbers::pi * schedule.arc[i] / 30.0);
    position[i] = Eigen::Vector3d(xy.x(), xy.y(), 0.3 + climb * (cruise - 0.3));
    const double moving = smoothstep((t - o.ground_s - DronePathOptions::kClimb - DronePathOptions::kHover) / 2.0) *
                          smoothstep((o.duration_s - DronePathOptions::kHover - t) / 2.0);
    const double wanted = r.heading + std::numbers::pi * schedule.turn_fraction[i] +
                          moving * kYawSweep * std::sin(2.0 * std::numbers::pi * t / kYawPeriod);
    // The yaw follows what it wants at no more than kYawRate: on tight bends the
    // multirotor flies a little sideways rather than exceed it.
    yaw[i] = i == 0 ? wanted
                    : yaw[i - 1] + std::clamp(std::remainder(wanted - yaw[i - 1], 2.0 * std::numbers::pi),
                                              -kYawRate * dt, kYawRate * dt);
  }
  std::vector<BodySample> samples(n);
  for (std::size_t i = 0; i < n; ++i) {
    // Acceleration over ±0.1 s: the route is linear between its 5 cm samples, so
    // a one-sample stencil would see kinks; the airframe's response is slower anyway.
    constexpr std::size_t kSpan = 20;
    Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();
    if (i >= kSpan && i + kSpan < n) {
      const double h = static_cast<double>(kSpan) * dt;
      acceleration = (position[i + kSpan] - 2.0 * position[i] + position[i - kSpan]) / (h * h);
    }
    // Tilt towards the acceleration in the yawed frame (small-angle multirotor model).
    const double c = std::cos(yaw[i]), s = std::sin(yaw[i]);
    const double forward = c * acceleration.x() + s * acceleration.y();
    const double lateral = -s * acceleration.x() + c * acceleration.y();
    const double t = static_cast<double>(i) * dt;
    // Turbulence once off the floor (on its legs the airframe stands still),
    // faded in over the climb's first second.
    const double airborne = o.ground_s > 0.0 ? smoothstep(t - o.ground_s) : 1.0;
    const double gust = airborne * 0.5 * std::numbers::pi / 180.0;
    const double pitch = std::atan2(forward, kGravity) + gust * value_noise3(o.seed ^ 0x4775ULL, t / 0.7, 0.5, 0.5);
    const double roll = -std::atan2(lateral, kGravity) + gust * value_noise3(o.seed ^ 0x4776ULL, t / 0.7, 0.5, 0.5);
    samples[i].position = position[i];
    samples[i].orientation = Eigen::AngleAxisd(yaw[i], Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  }
  return BodyTrack(std::move(samples));
}

}  // namespace adit::sim
