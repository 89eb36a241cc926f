#pragma once
// A person walking a scene's route with the scanner in hand (or on a short
// pole): stands still for two seconds (where an estimator takes gravity and
// the gyro's bias), walks at a steady pace with 1 s ramps, turns on the spot
// at the far end of an out-and-back route, and looks around on the way.
// Gait (a walker's typical figures, e.g. Winter, "Biomechanics and Motor
// Control of Human Movement", 4th ed., 2009): steps at 1.9 Hz, the hand rising
// and falling ±2.5 cm once per step (about ±3.6 m/s²), rolling ±2° and swaying
// ±1.5 cm sideways once per stride (two steps), pitching ±1.5° per step, the
// heading wobbling ±3° per stride, and slow ±3° drifts of where the scanner
// points. Glances: every 9-15 s the walker looks 60-100° to one side and back,
// at up to kMaxYawRate. The yaw never turns faster than kMaxYawRate (about
// the vertical), whatever adds up. Deterministic from the seed.

#include <cstdint>

#include "adit/sim/body_track.hpp"
#include "adit/sim/scene.hpp"

namespace adit::sim {

struct HandheldPathOptions {
  double duration_s = 60.0;
  double speed_mps = 1.3;        // walking pace, at most kMaxSpeed
  double lateral_offset_m = 0.0;
  double height_m = 1.40;        // the body (the hand) above the floor; the sensor sits 0.10 m above it
  double step_hz = 1.9;
  double bob_m = 0.025;
  std::uint64_t seed = 0;

  static constexpr double kMaxSpeed = 1.5;
  static constexpr double kMaxYawRate = 2.0943951023931953;  // 120°/s
  static constexpr double kTurnRate = 1.3;                   // rad/s, the turn on the spot (peak 1.5×, 112°/s)
  static constexpr double kHoldStart = 2.0;
  static constexpr double kRamp = 1.0;
};

BodyTrack handheld_path(const Scene& scene, const HandheldPathOptions& options);
double handheld_min_duration_s();

}  // namespace adit::sim
