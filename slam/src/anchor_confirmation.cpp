#include "adit/slam/anchor_confirmation.hpp"

namespace adit::slam {

LocalisationConfig confirmed_localisation(LocalisationConfig base) {
  base.min_overlap = 0.85;
  return base;
}

bool AnchorConfirmation::agrees(const Eigen::Isometry3d& anchor, const Eigen::Isometry3d& cloud_in_odometry) {
  if (candidate_) {
    const Eigen::Isometry3d apart = (*candidate_ * cloud_in_odometry).inverse() * (anchor * cloud_in_odometry);
    if (apart.translation().norm() <= config_.rival_m && Eigen::AngleAxisd(apart.linear()).angle() <= config_.rival_rad)
      return true;
  }
  candidate_ = anchor;
  return false;
}

}  // namespace adit::slam
