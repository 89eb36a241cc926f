#pragma once
// Levelling a frame by gravity: the odometry frame is the first scan's body
// frame, so its z is the payload's starting tilt away from plumb (decision
// 059). Given gravity's up as the odometry measured it in that frame (the
// LiDAR-inertial filter's gravity, or the accelerometer's settled mean), the
// exports are turned so that z is up (decision 060).

#include <Eigen/Geometry>

namespace adit::slam {

// The smallest rotation turning `up` (a direction in some frame, any
// length > 0, finite) onto +z, about the frame's origin: its axis up × z is
// horizontal, so the frame's heading changes only to second order in the
// tilt θ (at most θ²/4: 0.004° at 1°). Throws std::invalid_argument for a
// zero or non-finite `up`, or one at or below the horizontal (no payload
// starts on its side: such an up is a sign error, not a tilt).
Eigen::Isometry3d level_from_up(const Eigen::Vector3d& up);

// How far `frame` tilts z away from the vertical it levels to (rad): the
// angle between R·z and z.
double tilt_of(const Eigen::Isometry3d& frame);

}  // namespace adit::slam
