#include "adit/eval/kitti_drift.hpp"

#include <algorithm>
#include <cmath>

#include "adit/eval/path.hpp"
#include "adit/eval/pose_error.hpp"

namespace adit::eval {
namespace {

// The devkit's rotationError: acos of the clamped (trace - 1) / 2.
double devkit_rotation_error(const Eigen::Matrix3d& r) {
  const double d = 0.5 * (r.trace() - 1.0);
  return std::acos(std::clamp(d, -1.0, 1.0));
}

}  // namespace

std::optional<KittiDrift> kitti_drift(std::span<const slam::Pose> ref, std::span<const slam::Pose> est) {
  const std::size_t n = std::min(ref.size(), est.size());
  const std::vector<double> dist = path_distances(ref.first(n));
  KittiDrift out;
  for (std::size_t k = 0; k < kKittiLengths.size(); ++k) out.by_length[k].length = kKittiLengths[k];

  for (std::size_t first = 0; first < n; first += kKittiStep) {
    for (std::size_t k = 0; k < kKittiLengths.size(); ++k) {
      const double length = kKittiLengths[k];
      // First frame strictly beyond `length` of path (devkit lastFrameFromSegmentLength).
      const auto it =
          std::upper_bound(dist.begin() + static_cast<std::ptrdiff_t>(first), dist.end(), dist[first] + length);
      if (it == dist.end()) continue;
      const auto last = static_cast<std::size_t>(it - dist.begin());
      const slam::Pose delta_ref = ref[first].inverse() * ref[last];
      const slam::Pose delta_est = est[first].inverse() * est[last];
      const slam::Pose error = delta_est.inverse() * delta_ref;
      const double t_err = error.translation().norm() / length;
      const double r_err = devkit_rotation_error(error.linear()) / length;
      KittiLengthDrift& bucket = out.by_length[k];
      ++bucket.segments;
      bucket.translation_percent += 100.0 * t_err;
      bucket.rotation_deg_per_100m += 100.0 * rad_to_deg(r_err);
      ++out.segments;
      out.translation_percent += 100.0 * t_err;
      out.rotation_deg_per_100m += 100.0 * rad_to_deg(r_err);
    }
  }
  if (out.segments == 0) return std::nullopt;
  out.translation_percent /= static_cast<double>(out.segments);
  out.rotation_deg_per_100m /= static_cast<double>(out.segments);
  for (auto& bucket : out.by_length) {
    if (bucket.segments == 0) continue;
    bucket.translation_percent /= static_cast<double>(bucket.segments);
    bucket.rotation_deg_per_100m /= static_cast<double>(bucket.segments);
  }
  return out;
}

}  // namespace adit::eval
