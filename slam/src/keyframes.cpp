#include "adit/slam/keyframes.hpp"

#include <cmath>

namespace adit::slam {

bool KeyframeSelector::take(const Eigen::Isometry3d& pose) {
  if (last_) {
    const Eigen::Isometry3d delta = last_->inverse() * pose;
    const double angle_deg = Eigen::AngleAxisd(delta.linear()).angle() * 180.0 / M_PI;
    if (delta.translation().norm() < rule_.distance_m && angle_deg < rule_.angle_deg) return false;
  }
  last_ = pose;
  return true;
}

}  // namespace adit::slam
