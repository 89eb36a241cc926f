#pragma once
// Integer voxel coordinates of a point and their spatial hash.

#include <cmath>
#include <cstddef>
#include <cstdint>

#include <Eigen/Core>

namespace adit::slam {

struct VoxelKey {
  std::int32_t x = 0;
  std::int32_t y = 0;
  std::int32_t z = 0;
  friend bool operator==(const VoxelKey&, const VoxelKey&) = default;
};

// floor(x) as an integer, for |x| within int32 range (as static_cast of
// std::floor requires too). Without SSE4.1's roundss (not in baseline x86-64)
// std::floor is a software sequence of ~12 instructions; every point of a
// scan takes three, twice in downsampling and 27 times per plane search.
inline std::int32_t floor_to_int(float x) {
  const auto truncated = static_cast<std::int32_t>(x);  // towards zero
  return truncated - static_cast<std::int32_t>(x < static_cast<float>(truncated));
}

inline VoxelKey voxel_key(const Eigen::Vector3f& p, float inverse_voxel_size) {
  return {floor_to_int(p.x() * inverse_voxel_size), floor_to_int(p.y() * inverse_voxel_size),
          floor_to_int(p.z() * inverse_voxel_size)};
}

// Teschner et al., "Optimized Spatial Hashing for Collision Detection of
// Deformable Objects", VMV 2003: XOR of the coordinates times large primes.
inline std::uint32_t voxel_hash(const VoxelKey& key) {
  return (static_cast<std::uint32_t>(key.x) * 73856093U) ^ (static_cast<std::uint32_t>(key.y) * 19349663U) ^
         (static_cast<std::uint32_t>(key.z) * 83492791U);
}

// voxel_hash for std::unordered_map.
struct VoxelKeyHash {
  std::size_t operator()(const VoxelKey& key) const { return voxel_hash(key); }
};

}  // namespace adit::slam
