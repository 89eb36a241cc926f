#pragma once
// The two scalar errors of a pose difference E = Q^-1 P (reference Q,
// estimate P): the length of its translation and the angle of its rotation.

#include <vector>

#include "adit/slam/trajectory.hpp"

namespace adit::eval {

// Per-pose (APE) or per-pair (RPE) errors.
struct PoseErrors {
  std::vector<double> translation;   // metres
  std::vector<double> rotation_deg;  // degrees
};

// Rotation angle of R in radians, in [0, pi]: atan2(|vee(R - R^T)| / 2, (tr R - 1) / 2),
// which stays accurate near 0 and pi where acos((tr R - 1) / 2) does not.
double rotation_angle(const Eigen::Matrix3d& r);

inline double rad_to_deg(double rad) { return rad * (180.0 / 3.14159265358979323846); }

}  // namespace adit::eval
