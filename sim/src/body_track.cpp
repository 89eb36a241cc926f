#include "adit/sim/body_track.hpp"

#include <algorithm>
#include <cmath>

namespace adit::sim {

BodyTrack::BodyTrack(std::vector<BodySample> samples) : samples_(std::move(samples)) {
  duration_ = samples_.size() > 1 ? static_cast<double>(samples_.size() - 1) / kRate : 0.0;
}

Eigen::Isometry3d BodyTrack::pose(double t) const {
  const double x = std::clamp(t, 0.0, duration_) * kRate;
  const auto i = std::min(static_cast<std::size_t>(x), samples_.size() > 1 ? samples_.size() - 2 : 0);
  const double f = std::min(x - static_cast<double>(i), 1.0);
  const BodySample& a = samples_[i];
  const BodySample& b = samples_[std::min(i + 1, samples_.size() - 1)];
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = a.position + f * (b.position - a.position);
  pose.linear() = a.orientation.slerp(f, b.orientation).toRotationMatrix();
  return pose;
}

}  // namespace adit::sim
