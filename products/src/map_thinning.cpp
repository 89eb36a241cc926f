#include "adit/products/map_thinning.hpp"

#include <cmath>

namespace adit::products {

// A brick of 4³ voxels per slot: the 30-minute drive's 3.8 M voxels of 5 cm
// lie in 254 k bricks, 8 MB of table (the set's keys wrap only for points
// 420 km apart at 5 cm).
VoxelThinner::VoxelThinner(double voxel_m, std::size_t expected_points)
    : inverse_(voxel_m > 0.0 ? 1.0 / voxel_m : 0.0), seen_(voxel_m > 0.0 ? expected_points / 16 : 0) {}

bool VoxelThinner::keep(const protocol::MapPoint& p) {
  if (inverse_ == 0.0 || !std::isfinite(p.x + p.y + p.z)) return true;  // read_map refuses these; kept, not cast
  return seen_.insert({static_cast<std::int64_t>(std::floor(p.x * inverse_)),
                       static_cast<std::int64_t>(std::floor(p.y * inverse_)),
                       static_cast<std::int64_t>(std::floor(p.z * inverse_))});
}

std::size_t thin_to_voxels(std::vector<protocol::MapPoint>& points, double voxel_m) {
  VoxelThinner thinner(voxel_m, points.size());
  std::size_t out = 0;
  for (const protocol::MapPoint& p : points)
    if (thinner.keep(p)) points[out++] = p;
  const std::size_t dropped = points.size() - out;
  points.resize(out);
  return dropped;
}

}  // namespace adit::products
