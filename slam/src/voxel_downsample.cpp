#include "adit/slam/voxel_downsample.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace adit::slam {

VoxelDownsampler::VoxelDownsampler(std::size_t max_points)
    : mask_(std::bit_ceil(std::max<std::size_t>(2 * max_points, 16)) - 1),  // load factor ≤ 1/2
      max_points_(max_points),
      slots_(mask_ + 1) {}

std::size_t VoxelDownsampler::downsample(std::span<const Eigen::Vector3f> in, float voxel_size_m,
                                         std::vector<Eigen::Vector3f>& out) {
  return downsample(in, {}, voxel_size_m, out, times_unused_);
}

std::size_t VoxelDownsampler::downsample(std::span<const Eigen::Vector3f> in, std::span<const float> in_times,
                                         float voxel_size_m, std::vector<Eigen::Vector3f>& out,
                                         std::vector<float>& out_times) {
  return downsample_if(in, in_times, voxel_size_m, out, out_times, [](const Eigen::Vector3f&) { return true; });
}

std::size_t VoxelDownsampler::downsample(std::span<const Eigen::Vector3f> in, std::span<const float> in_times,
                                         float voxel_size_m, std::vector<Eigen::Vector3f>& out,
                                         std::vector<float>& out_times, float min_range_m, float max_range_m) {
  const float min2 = min_range_m * min_range_m;
  const float max2 = max_range_m * max_range_m;
  return downsample_if(in, in_times, voxel_size_m, out, out_times, [&](const Eigen::Vector3f& p) {
    const float r2 = p.squaredNorm();
    return std::isfinite(r2) && r2 >= min2 && r2 <= max2;
  });
}

template <typename Keep>
std::size_t VoxelDownsampler::downsample_if(std::span<const Eigen::Vector3f> in, std::span<const float> in_times,
                                            float voxel_size_m, std::vector<Eigen::Vector3f>& out,
                                            std::vector<float>& out_times, Keep&& keep) {
  out.clear();
  out_times.clear();
  const bool timed = in_times.size() == in.size();
  if (++generation_ == 0) {  // wrapped after 2^32 calls: forget every mark once
    for (Slot& s : slots_) s.generation = 0;
    generation_ = 1;
  }
  // Only the first bit_ceil(2·n) slots are used (load factor ≤ 1/2 still):
  // a 120 k-point scan then probes 4 MB of table, not the 16 MB sized for
  // max_points, and far more of it stays in cache. The slots beyond carry
  // older generations, which read as empty whatever mask a later call uses.
  const std::size_t mask =
      std::min(mask_, std::bit_ceil(std::max<std::size_t>(2 * std::min(in.size(), max_points_), 16)) - 1);
  const float inverse = 1.0F / voxel_size_m;
  // Consecutive points of a scan often fall in one voxel: the previous point
  // already took it (or found it taken), so the lookup can be skipped.
  VoxelKey previous{};
  bool has_previous = false;
  for (std::size_t k = 0; k < in.size(); ++k) {
    const Eigen::Vector3f& p = in[k];
    if (out.size() >= max_points_) break;
    if (!keep(p)) continue;
    const VoxelKey key = voxel_key(p, inverse);
    if (has_previous && key == previous) continue;
    previous = key;
    has_previous = true;
    for (std::size_t i = voxel_hash(key) & mask;; i = (i + 1) & mask) {
      Slot& slot = slots_[i];
      if (slot.generation != generation_) {
        slot = {key, generation_};
        out.push_back(p);  // within reserved capacity: no allocation
        if (timed) out_times.push_back(in_times[k]);
        break;
      }
      if (slot.key == key) break;
    }
  }
  return out.size();
}

}  // namespace adit::slam
