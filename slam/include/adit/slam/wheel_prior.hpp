#pragma once
// The motion prior wheel odometry gives the LiDAR odometry between two scans:
// the planar body motion from the integrated wheel pose at the first scan to
// the one at the second, with a covariance that grows with the distance and
// the turn. The wheels say nothing about height, roll and pitch, so those are
// loose. (Error model after Siegwart et al., "Introduction to Autonomous
// Mobile Robots", §5.2.4: variance proportional to the travel; the constants
// are in wheel_prior.cpp and listed in docs/ODOMETRY.md.)

#include "adit/slam/odometry.hpp"
#include "adit/slam/pose2.hpp"

namespace adit::slam {

// `distance`: metres the wheels travelled between the two poses (≥ 0).
// Delta and covariance are in the body frame (the wheel odometry's).
MotionPrior wheel_motion_prior(const Pose2& from, const Pose2& to, double distance);

}  // namespace adit::slam
