#pragma once
// Where along a scene's route a platform is at each trajectory sample: smooth
// speed ramps, whole laps on a loop when there is time for one (ending where
// it started, every place revisited), otherwise out, a turn on the spot and
// back the same way. Shared by the robot and the drone.

#include <vector>

#include <Eigen/Core>

#include "adit/sim/scene.hpp"

namespace adit::sim {

struct RouteSchedule {
  std::vector<double> arc;            // metres along the route, per BodyTrack sample
  std::vector<double> turn_fraction;  // 0 outbound, 1 returning, in between while turning on the spot
};

struct ScheduleOptions {
  double duration_s = 60.0;
  double speed_mps = 1.0;
  double turn_rate_rps = 0.6;
  double ramp_s = 1.0;
  double hold_start_s = 0.0;  // standing (hovering) before moving off
  double hold_end_s = 0.0;    // and after arriving
};

RouteSchedule route_schedule(const Route& route, const ScheduleOptions& options);
// The shortest duration route_schedule accepts (a turn, two ramps per leg, the holds).
double min_schedule_duration_s(const ScheduleOptions& options);

struct RoutePoint {
  Eigen::Vector2d position;
  double heading = 0.0;  // rad, direction of travel along the route
};
RoutePoint route_at(const Route& route, double s);

double smoothstep(double x);

}  // namespace adit::sim
