#pragma once
// A differential-drive robot driving a scene's route: smooth speed ramps, the
// heading of the route, bumps of the rough floor that pitch and roll the body.
// On a loop it drives whole laps (ending where it started, having revisited
// everything); when there is no time for a lap, or on an open route, it drives
// out, turns on the spot and comes back along the same way.

#include <cstdint>

#include "adit/sim/scene.hpp"
#include "adit/sim/body_track.hpp"

namespace adit::sim {

struct RobotPathOptions {
  double duration_s = 60.0;
  double speed_mps = 1.0;         // cruise speed, at most kMaxSpeed
  double lateral_offset_m = 0.0;  // from the route's centre line, + to the left
  double bump_deg = 1.0;          // roll/pitch amplitude from the floor
  double body_height_m = 0.1651;  // body origin above the floor (the axle)
  double track_m = 0.555;         // between the wheels (as WheelOptions::track_m)
  std::uint64_t seed = 0;

  static constexpr double kMaxSpeed = 1.5;
  static constexpr double kTurnRate = 0.6;  // rad/s on the spot
  static constexpr double kRamp = 1.0;      // s to reach cruise speed
  // s standing still before moving off, as a crew starts a survey: the
  // accelerometer's gravity then needs no motion removed (slam/gravity.hpp;
  // docs/decisions/003-gravity-settle.md).
  static constexpr double kHoldStart = 1.0;
};

BodyTrack robot_path(const Scene& scene, const RobotPathOptions& options);

// The shortest duration robot_path accepts for the scene's route (a turn and two ramps).
double robot_min_duration_s();

}  // namespace adit::sim
