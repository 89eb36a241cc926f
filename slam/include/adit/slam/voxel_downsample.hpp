#pragma once
// Voxel-grid downsampling that keeps the first point to land in each voxel
// (KISS-ICP, Vizzo et al. 2023, §III-B: the original points, not centroids, so
// no point is invented). Storage is fixed at construction: a key table marked
// with a generation number, so a new scan needs no clearing and no allocation.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "adit/slam/voxel_key.hpp"

namespace adit::slam {

class VoxelDownsampler {
 public:
  // max_points: the most points one call may keep; larger inputs keep the
  // first max_points voxels' representatives.
  explicit VoxelDownsampler(std::size_t max_points);

  // Writes into `out` (which must have capacity, see reserve_output) one point
  // per occupied voxel of edge voxel_size_m, in input order; returns the count.
  std::size_t downsample(std::span<const Eigen::Vector3f> in, float voxel_size_m, std::vector<Eigen::Vector3f>& out);
  // The same, carrying each kept point's time (`in_times` as long as `in`) into `out_times`.
  std::size_t downsample(std::span<const Eigen::Vector3f> in, std::span<const float> in_times, float voxel_size_m,
                         std::vector<Eigen::Vector3f>& out, std::vector<float>& out_times);
  // The same over the points of `in` that are finite and whose range lies in
  // [min_range_m, max_range_m], the others skipped: a raw scan is filtered and
  // downsampled in one pass, without a filtered copy (120 k points on a 64-beam scan).
  std::size_t downsample(std::span<const Eigen::Vector3f> in, std::span<const float> in_times, float voxel_size_m,
                         std::vector<Eigen::Vector3f>& out, std::vector<float>& out_times, float min_range_m,
                         float max_range_m);

 private:
  template <typename Keep>
  std::size_t downsample_if(std::span<const Eigen::Vector3f> in, std::span<const float> in_times, float voxel_size_m,
                            std::vector<Eigen::Vector3f>& out, std::vector<float>& out_times, Keep&& keep);
  struct Slot {
    VoxelKey key;
    std::uint32_t generation = 0;  // the slot is taken in this call only if equal to generation_
  };
  std::size_t mask_;
  std::size_t max_points_;
  std::uint32_t generation_ = 0;
  std::vector<Slot> slots_;
  std::vector<float> times_unused_;  // the untimed overload's (empty) time output
};

}  // namespace adit::slam
