#pragma once
// A multirotor flying a scene's route: sits on the floor with its rotors
// running (`ground_s`, as every real take-off starts), climbs and hovers, then
// flies the route (laps, or out, a yaw turn in hover and back) at up to
// 2 m/s, rising and sinking along the way, sweeping its yaw ±25° about the
// direction of travel (≤ 90°/s), and hovers again at the end. Roll and pitch
// follow the accelerations as a multirotor's do (tilt = atan(a/g)), plus a
// little turbulence.

#include <cstdint>

#include "adit/sim/scene.hpp"
#include "adit/sim/body_track.hpp"

namespace adit::sim {

struct DronePathOptions {
  double duration_s = 60.0;
  double speed_mps = 1.0;        // cruise speed, at most kMaxSpeed
  double lateral_offset_m = 0.0;
  double altitude_m = 2.0;       // mean flight height above the floor
  double ground_s = 0.0;         // s on the floor, rotors running, before the climb
  std::uint64_t seed = 0;

  static constexpr double kMaxSpeed = 2.0;
  static constexpr double kMaxYawRate = 1.5707963267948966;  // 90°/s
  static constexpr double kTurnRate = 0.7;                   // rad/s, the turn in hover (peak 1.5×)
  static constexpr double kClimb = 4.0;                      // s from the floor to altitude
  static constexpr double kHover = 2.0;                      // s hovering before and after
};

BodyTrack drone_path(const Scene& scene, const DronePathOptions& options);
double drone_min_duration_s(const DronePathOptions& options);

}  // namespace adit::sim
