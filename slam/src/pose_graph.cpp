// The odometry edges' drift model (pose_graph.hpp).
#include "adit/slam/pose_graph.hpp"

#include <Eigen/Geometry>

namespace adit::slam {

Matrix6d odometry_information(const Eigen::Isometry3d& motion, const OdometryNoise& noise) {
  const double distance = motion.translation().norm();
  const double angle = Eigen::AngleAxisd(motion.linear()).angle();
  const double st = noise.sigma_floor_m + noise.sigma_per_m * distance;
  const double sr = noise.sigma_floor_rad + noise.sigma_rad_per_m * distance + noise.sigma_rad_per_rad * angle;
  Vector6d diagonal;
  diagonal << Eigen::Vector3d::Constant(1.0 / (st * st)), Eigen::Vector3d::Constant(1.0 / (sr * sr));
  return diagonal.asDiagonal();
}

}  // namespace adit::slam
