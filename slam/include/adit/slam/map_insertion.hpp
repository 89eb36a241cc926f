#pragma once
// When a scan may enter a scan-to-map registration's map: only once the body
// has moved or turned since the last scan that did.
//
// A sensor standing still (a drone on the floor before take-off or
// hovering, a robot's first second, a surveyor waiting) sees the same rings
// again and again. Each pass adds points between the last ones along the
// rings, until the nearest points of a floor or roof patch all lie on one
// ring and its plane is refused as a line (registration.hpp): the height is
// then unobserved when the motion begins, and the odometry stays on the
// floor while the sensor climbs. Insertion by motion is how keyframe-based
// LiDAR odometry fills its map (LIO-SAM, Shan et al., IROS 2020, §III-E,
// at 1 m / 0.2 rad); here the steps are a few centimetres, so a moving
// sensor still adds every scan. Evidence: docs/decisions/033-map-insertion-after-motion.md.

#include <Eigen/Geometry>

namespace adit::slam {

struct MapInsertionStep {
  double step_m = 0.05;    // travel since the last scan the map took
  double step_rad = 0.01;  // or turn (10 m away: 0.1 m)
};

inline bool moved_since(const Eigen::Isometry3d& added_at, const Eigen::Isometry3d& pose, const MapInsertionStep& step) {
  const Eigen::Isometry3d moved = added_at.inverse() * pose;
  return moved.translation().norm() >= step.step_m || Eigen::AngleAxisd(moved.linear()).angle() >= step.step_rad;
}

}  // namespace adit::slam
