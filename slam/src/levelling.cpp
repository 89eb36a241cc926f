// Levelling a frame by gravity (levelling.hpp).
#include "adit/slam/levelling.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace adit::slam {

Eigen::Isometry3d level_from_up(const Eigen::Vector3d& up) {
  const double n = up.norm();
  if (!std::isfinite(n) || !(n > 0.0)) throw std::invalid_argument("level_from_up: up is zero or not finite");
  const Eigen::Vector3d u = up / n;
  if (u.z() <= 0.0) throw std::invalid_argument("level_from_up: up points below the horizontal");
  Eigen::Isometry3d level = Eigen::Isometry3d::Identity();
  level.linear() = Eigen::Quaterniond::FromTwoVectors(u, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return level;
}

double tilt_of(const Eigen::Isometry3d& frame) {
  return std::acos(std::clamp((frame.linear() * Eigen::Vector3d::UnitZ()).z(), -1.0, 1.0));
}

}  // namespace adit::slam
