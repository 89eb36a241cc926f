#include "adit/eval/ape.hpp"

#include <algorithm>

#include "adit/eval/pose_error.hpp"

namespace adit::eval {

PoseErrors absolute_pose_errors(std::span<const slam::Pose> ref, std::span<const slam::Pose> est) {
  PoseErrors out;
  const std::size_t n = std::min(ref.size(), est.size());
  out.translation.reserve(n);
  out.rotation_deg.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    out.translation.push_back((ref[i].translation() - est[i].translation()).norm());
    out.rotation_deg.push_back(rad_to_deg(rotation_angle(ref[i].linear().transpose() * est[i].linear())));
  }
  return out;
}

}  // namespace adit::eval
