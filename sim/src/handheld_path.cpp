#include "adit/sim/handheld_path.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "adit/sim/hash_noise.hpp"
#include "adit/sim/route_schedule.hpp"

namespace adit::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

ScheduleOptions schedule_options(const HandheldPathOptions& o) {
  ScheduleOptions s;
  s.duration_s = o.duration_s;
  s.speed_mps = o.speed_mps;
  s.turn_rate_rps = HandheldPathOptions::kTurnRate;
  s.ramp_s = HandheldPathOptions::kRamp;
  s.hold_start_s = HandheldPathOptions::kHoldStart;
  return s;
}

// Looking aside and back: glance j starts at about 6 + 12·j s (±3 s), turns
// 60-100° to a random side, holds 0.6 s and turns back. Each half is a
// smoothstep whose peak rate (1.5 × angle / time) asks for 115 % of the
// yaw-rate limit, so the limit is reached and held for a moment.
double glance(std::uint64_t seed, double t) {
  constexpr double kPeriod = 12.0, kHold = 0.6;
  const NoiseStream draw(seed, 0x476C616EULL);
  const auto j0 = static_cast<std::int64_t>(std::floor((t - 6.0) / kPeriod));
  for (std::int64_t j = std::max<std::int64_t>(j0 - 1, 0); j <= j0 + 1; ++j) {
    const auto u = static_cast<std::uint64_t>(j) * 4;
    const double start = 6.0 + kPeriod * static_cast<double>(j) + 3.0 * (2.0 * draw.uniform(u) - 1.0);
    const double angle = (60.0 + 40.0 * draw.uniform(u + 1)) * kDeg * (draw.uniform(u + 2) < 0.5 ? -1.0 : 1.0);
    const double half = 1.5 * std::abs(angle) / (1.15 * HandheldPathOptions::kMaxYawRate);
    const double x = t - start;
    if (x < 0.0 || x > 2.0 * half + kHold) continue;
    return angle * (smoothstep(x / half) - smoothstep((x - half - kHold) / half));
  }
  return 0.0;
}

}  // namespace

double handheld_min_duration_s() { return min_schedule_duration_s(schedule_options(HandheldPathOptions{})); }

BodyTrack handheld_path(const Scene& scene, const HandheldPathOptions& o) {
  const RouteSchedule schedule = route_schedule(scene.route, schedule_options(o));
  const std::vector<double>& arc = schedule.arc;
  const std::size_t n = arc.size();
  const double dt = 1.0 / BodyTrack::kRate;
  std::vector<BodySample> samples(n);
  double phase = 0.0;  // of the gait, rad: one step per 2π
  double yaw = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * dt;
    // How much of the pace the walker has (0 standing or turning on the spot, 1 cruising).
    const std::size_t a = i > 0 ? i - 1 : i, b = std::min(i + 1, n - 1);
    const double speed = b > a ? std::abs(arc[b] - arc[a]) / (static_cast<double>(b - a) * dt) : 0.0;
    const double walking = std::clamp(speed / o.speed_mps, 0.0, 1.0);
    if (i > 0) phase += 2.0 * std::numbers::pi * o.step_hz * walking * dt;
    const double stride = 0.5 * phase;  // one stride per two steps
    const RoutePoint r = route_at(scene.route, arc[i]);
    const Eigen::Vector2d left(-std::sin(r.heading), std::cos(r.heading));
    const double sway = 0.015 * walking * std::sin(stride);
    const Eigen::Vector2d xy = r.position + left * (o.lateral_offset_m + sway);
    const double z = o.height_m + o.bob_m * walking * std::cos(phase);
    // Heading: the route's (turned round on an out-and-back), the gait's
    // wobble and the glances, followed at no more than the yaw-rate limit.
    const double wanted = r.heading + std::numbers::pi * schedule.turn_fraction[i] +
                          walking * (3.0 * kDeg * std::sin(stride + 0.4) + glance(o.seed, t));
    yaw = i == 0 ? wanted
                 : yaw + std::clamp(std::remainder(wanted - yaw, 2.0 * std::numbers::pi),
                                    -HandheldPathOptions::kMaxYawRate * dt, HandheldPathOptions::kMaxYawRate * dt);
    // Roll and pitch: the gait's, plus slow drifts of the hand (±3° pitch,
    // ±1.5° roll over ~3 s), a fifth of that while standing at the start.
    const double drift = 0.2 + 0.8 * smoothstep(t - HandheldPathOptions::kHoldStart);
    const double roll = walking * 2.0 * kDeg * std::sin(stride) +
                        drift * 1.5 * kDeg * value_noise3(o.seed ^ 0x48526F6CULL, t / 3.0, 0.5, 0.5);
    const double pitch = walking * 1.5 * kDeg * std::sin(phase + 1.0) +
                         drift * 3.0 * kDeg * value_noise3(o.seed ^ 0x48506974ULL, t / 3.0, 0.5, 0.5);
    samples[i].position = Eigen::Vector3d(xy.x(), xy.y(), z);
    samples[i].orientation = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
    samples[i].speed_mps = speed;
  }
  return BodyTrack(std::move(samples));
}

}  // namespace adit::sim
