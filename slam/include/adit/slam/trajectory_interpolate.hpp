#pragma once
// A trajectory's pose at any instant between its stamps. In slam/ (not eval/)
// because the session products, which aditd is to run, place recorded scans
// with it, and aditd does not link eval; eval/interpolate.hpp forwards here.

#include <optional>

#include "adit/slam/trajectory.hpp"

namespace adit::slam {

// The pose at time t: position linear and orientation by slerp (Shoemake,
// "Animating rotation with quaternion curves", SIGGRAPH 1985) between the two
// poses whose stamps bracket t. nullopt when the trajectory is untimed or
// empty, or t lies outside [first stamp, last stamp].
std::optional<Pose> interpolate_pose(const Trajectory& trajectory, double t);

}  // namespace adit::slam
