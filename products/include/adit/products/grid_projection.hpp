#pragma once
// The 2D occupancy grid from the 3D one: a cell is occupied when a kept
// (non-ground, not an outlier) map point lies over it
// within the band of heights above the ground that blocks a robot; free when
// a free voxel of the octree lies over it within that band, or a ground
// point lies in it (the floor was seen there, so nothing stood over it: the
// rule octomap_server uses for its ground points), and no such point does;
// unknown otherwise. Occupied cells come from the points, not
// the voxels, so the grid can be finer than the octree (down to 0.01 m).

#include <cstdint>
#include <span>

#include <Eigen/Core>

#include "adit/products/grid_2d.hpp"
#include "adit/products/ground.hpp"
#include "adit/products/occupancy_3d.hpp"

namespace adit::products {

struct ProjectionOptions {
  double resolution_m = 0.05;
  double band_low_m = 0.15;
  double band_high_m = 2.0;
};

// 2D line-of-sight fill (how a 2D laser scan's free space is made): from each
// viewpoint, rays over the grid every 0.25° (walked cell by cell, Amanatides
// and Woo 1987) mark unknown cells free up to the
// first occupied cell (dilated by one cell, so a pinhole in a wall does not
// leak), but only when they meet one within range_m: free space bounded by an
// observed obstacle. It fills the floor between the sparse rings the 3D rays
// leave in large rooms. Returns the cells it made free.
std::size_t fill_line_of_sight(Grid2d& grid, std::span<const Eigen::Vector3f> viewpoints, double range_m,
                               double viewpoint_step_m);

Grid2d project_to_grid(const Occupancy3d& occupancy, std::span<const Eigen::Vector3f> points,
                       std::span<const std::uint8_t> obstacle, std::span<const std::uint8_t> floor,
                       const GroundModel& ground,
                       const ProjectionOptions& options);

}  // namespace adit::products
