// Where an earlier pass mapped a point's place (revisit_filter.hpp).
#include "adit/slam/revisit_filter.hpp"

#include <cmath>
#include <limits>

namespace adit::slam {

void RevisitFilter::follow(std::shared_ptr<const CorrectionTrack> track) {
  track_ = std::move(track);
  cells_.clear();
  if (track_ == nullptr) return;
  const std::vector<Eigen::Vector3d>& positions = track_->graph_positions();
  const auto per_cell = static_cast<float>(1.0 / config_.radius_m);
  for (std::size_t k = 0; k < positions.size(); ++k)
    cells_[voxel_key(positions[k].cast<float>(), per_cell)].push_back(static_cast<std::uint32_t>(k));
}

void RevisitFilter::place_in_earlier_pass(std::span<const Eigen::Vector3f> points, std::int64_t stamp_ns,
                                          std::vector<Eigen::Vector3f>& earlier) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  earlier.assign(points.size(), Eigen::Vector3f::Constant(kNaN));
  if (track_ == nullptr || track_->empty()) return;
  const Eigen::Isometry3d now = track_->at(stamp_ns);
  const Eigen::Isometry3f now_f = now.cast<float>();
  const std::int64_t newest = stamp_ns - static_cast<std::int64_t>(std::llround(config_.min_age_s * 1e9));
  block_transform_.clear();
  keyframe_transform_.clear();
  transforms_.clear();
  const float per_block = 1.0F / config_.block_m;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) continue;
    const Eigen::Vector3f graph_point = now_f * points[i];
    auto [block, inserted] = block_transform_.try_emplace(voxel_key(graph_point, per_block), -1);
    if (inserted) {
      const std::int64_t k = first_pass_keyframe(graph_point, newest);
      if (k < 0) continue;
      auto [transform, fresh] = keyframe_transform_.try_emplace(k, static_cast<std::int32_t>(transforms_.size()));
      if (fresh) transforms_.push_back((track_->corrections()[static_cast<std::size_t>(k)].inverse() * now).cast<float>());
      block->second = transform->second;
    }
    if (block->second >= 0) earlier[i] = transforms_[static_cast<std::size_t>(block->second)] * points[i];
  }
}

// The first pass through the place: the oldest keyframe within radius_m (the
// cells around the point hold every keyframe that can be, oldest first),
// then the nearest of those that follow it while they stay within radius_m
// (one visit). A later pass added only what no pass before it had mapped, so
// the first holds the place whole.
std::int64_t RevisitFilter::first_pass_keyframe(const Eigen::Vector3f& graph_point, std::int64_t newest_ns) const {
  const Eigen::Vector3d p = graph_point.cast<double>();
  const std::vector<Eigen::Vector3d>& positions = track_->graph_positions();
  const std::vector<std::int64_t>& stamps = track_->stamps_ns();
  const double r2 = config_.radius_m * config_.radius_m;
  const VoxelKey centre = voxel_key(graph_point, static_cast<float>(1.0 / config_.radius_m));
  std::size_t first = positions.size();
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        const auto cell = cells_.find({centre.x + dx, centre.y + dy, centre.z + dz});
        if (cell == cells_.end()) continue;
        for (const std::uint32_t k : cell->second) {
          if (k >= first || stamps[k] > newest_ns) break;
          if ((positions[k] - p).squaredNorm() <= r2) {
            first = k;
            break;
          }
        }
      }
  if (first == positions.size()) return -1;
  std::size_t nearest = first;
  double best = (positions[first] - p).squaredNorm();
  for (std::size_t k = first + 1; k < positions.size() && stamps[k] <= newest_ns; ++k) {
    const double d2 = (positions[k] - p).squaredNorm();
    if (d2 > r2) break;  // the visit ended
    if (d2 < best) {
      best = d2;
      nearest = k;
    }
  }
  return static_cast<std::int64_t>(nearest);
}

}  // namespace adit::slam
