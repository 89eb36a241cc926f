#include "adit/products/map_thinning.hpp"

#include <cmath>

#include "adit/products/voxel_brick_set.hpp"

namespace adit::products {

std::size_t thin_to_voxels(std::vector<protocol::MapPoint>& points, double voxel_m) {
  if (!(voxel_m > 0.0)) return 0;
  const double inverse = 1.0 / voxel_m;
  // A brick of 4³ voxels per slot: the 30-minute drive's 3.8 M voxels of
  // 5 cm lie in 254 k bricks, 8 MB of table (the set's keys wrap only for
  // points 420 km apart at 5 cm).
  VoxelBrickSet seen(points.size() / 16);
  std::size_t out = 0;
  for (const protocol::MapPoint& p : points) {
    const bool kept = !std::isfinite(p.x + p.y + p.z) ||  // read_map refuses these; kept, not cast
                      seen.insert({static_cast<std::int64_t>(std::floor(p.x * inverse)),
                                   static_cast<std::int64_t>(std::floor(p.y * inverse)),
                                   static_cast<std::int64_t>(std::floor(p.z * inverse))});
    if (kept) points[out++] = p;
  }
  const std::size_t dropped = points.size() - out;
  points.resize(out);
  return dropped;
}

}  // namespace adit::products
