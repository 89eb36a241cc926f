#pragma once
// A trajectory's pose at any instant between its stamps.

#include <optional>

#include "adit/slam/trajectory.hpp"

namespace adit::eval {

// The pose at time t: position linear and orientation by slerp (Shoemake,
// "Animating rotation with quaternion curves", SIGGRAPH 1985) between the two
// poses whose stamps bracket t. nullopt when the trajectory is untimed or
// empty, or t lies outside [first stamp, last stamp].
std::optional<slam::Pose> interpolate_pose(const slam::Trajectory& trajectory, double t);

}  // namespace adit::eval
