#include "adit/slam/trajectory_interpolate.hpp"

#include <algorithm>

namespace adit::slam {

std::optional<Pose> interpolate_pose(const Trajectory& trajectory, double t) {
  const auto& stamps = trajectory.stamps;
  if (!trajectory.timed || stamps.empty() || !(t >= stamps.front() && t <= stamps.back())) return std::nullopt;
  // The first stamp >= t; an exact match needs no blending.
  const auto after = std::lower_bound(stamps.begin(), stamps.end(), t);
  const auto j = static_cast<std::size_t>(after - stamps.begin());
  if (*after == t || j == 0) return trajectory.poses[j];
  const std::size_t i = j - 1;
  const double f = (t - stamps[i]) / (stamps[j] - stamps[i]);
  const Pose& a = trajectory.poses[i];
  const Pose& b = trajectory.poses[j];
  Pose pose = Pose::Identity();
  pose.translation() = a.translation() + f * (b.translation() - a.translation());
  pose.linear() = Eigen::Quaterniond(a.linear()).slerp(f, Eigen::Quaterniond(b.linear())).toRotationMatrix();
  return pose;
}

}  // namespace adit::slam
