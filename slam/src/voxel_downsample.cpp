#include "adit/slam/voxel_downsample.hpp"

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
  out.clear();
  out_times.clear();
  const bool timed = in_times.size() == in.size();
  if (++generation_ == 0) {  // wrapped after 2^32 calls: forget every mark once
    for (Slot& s : slots_) s.generation = 0;
    generation_ = 1;
  }
  const float inverse = 1.0F / voxel_size_m;
  for (std::size_t k = 0; k < in.size(); ++k) {
    const Eigen::Vector3f& p = in[k];
    if (out.size() >= max_points_) break;
    const VoxelKey key = voxel_key(p, inverse);
    for (std::size_t i = voxel_hash(key) & mask_;; i = (i + 1) & mask_) {
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
