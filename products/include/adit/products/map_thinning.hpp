#pragma once
// One map point per voxel of the session's own map, in the frame the map was
// exported in. aditd keeps one point per voxel (map.voxel_m) in the
// odometry's frame; where the loop closure moved the map (map.loops_move_map)
// or the export levelled it, the same place mapped on several laps holds a
// point from each lap: a 30-minute drive of seven laps exported 14.7 M points
// in 3.8 M voxels of 5 cm. Every product step costs per point and none gains
// from more than one point per map voxel (the octree is 10 cm, the grid 5 cm).
// As aditd's map and the odometry's downsampling (KISS-ICP, Vizzo et al.
// 2023, §III-B), the first point in each voxel is kept, not a centroid: no
// point is invented. docs/decisions/063-products-one-point-per-map-voxel.md.

#include <cstddef>
#include <vector>

#include "adit/products/voxel_brick_set.hpp"
#include "adit/protocol/map_point.hpp"

namespace adit::products {

// Points offered one by one (as a map file is read, protocol::MapFileReader):
// keep() says whether each is the first in its voxel.
class VoxelThinner {
 public:
  // voxel_m ≤ 0: every point is kept. `expected_points` sizes the table.
  VoxelThinner(double voxel_m, std::size_t expected_points);
  bool keep(const protocol::MapPoint& p);

 private:
  double inverse_ = 0.0;  // 1 / voxel_m; 0: keep all
  VoxelBrickSet seen_;
};

// Keeps the first point (in order) of each voxel of edge `voxel_m`, in their
// order; returns how many were dropped. voxel_m ≤ 0: every point is kept.
std::size_t thin_to_voxels(std::vector<protocol::MapPoint>& points, double voxel_m);

}  // namespace adit::products
