#pragma once
// Scoring a 2D occupancy grid against a scene mesh (the simulator's
// scene.ply). The truth is rasterised on the grid's own lattice (its origin,
// at `cell_m`): a cell is occupied when the scene's surfaces cross it at some
// height within the band above the floor (the mesh sliced every 0.1 m, the
// slices' segments drawn into the lattice); free when it is reached from the
// true path without crossing an occupied cell (4-connected flood fill). Only
// what a sensor on the path could have seen is scored: cells within
// `max_range_m` of the path that a 2D ray from the path reaches (free cells
// before the first occupied one, and that occupied one). Then, within that
// range: IoU of free cells, IoU of occupied cells, and a tolerant occupied
// IoU where a cell within one cell of the other side's counts as matched.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "adit/eval/mesh_distance.hpp"

namespace adit::eval {

// A grid as nav_msgs/OccupancyGrid holds it: -1 unknown, 0 free, 100 occupied,
// row 0 at origin_y, in the map frame.
struct GridView {
  double resolution_m = 0.05;
  double origin_x = 0.0, origin_y = 0.0;
  int width = 0, height = 0;
  std::span<const std::int8_t> cells;
};

struct GridTruthOptions {
  double cell_m = 0.05;       // the truth's lattice
  double floor_z = 0.0;       // the scene's floor height, world frame
  double band_low_m = 0.15;   // the heights sliced, above the floor
  double band_high_m = 2.0;
  double max_range_m = 20.0;  // cells farther from the path are not scored
  double path_step_m = 0.5;   // viewpoints along the path for the 2D visibility
  int rays = 2880;            // per viewpoint
};

// What the grid and the truth say of one lattice cell (GridTruthScore::cells).
enum class CellAgreement : std::uint8_t {
  unscored,              // out of range of the path
  free_both,
  free_truth_unknown,    // free in the truth, unknown in the grid
  occupied_grid_only,    // occupied in the grid with no true wall within a cell (the truth free or unseen there)
  occupied_both,         // within one cell of each other
  occupied_truth_only,   // a seeable true wall the grid has nothing of within a cell
  free_grid_only,        // free in the grid where the truth is not seeable free
  unseen_both,           // in range, neither knows it
};

struct GridTruthScore {
  std::size_t truth_free = 0, truth_occupied = 0;   // visible, in range
  std::size_t grid_free = 0, grid_occupied = 0;     // in range, on the truth lattice
  double iou_free = 0.0;
  double iou_occupied = 0.0;
  double iou_occupied_within_1_cell = 0.0;
  double iou_known = 0.0;  // seen (free or occupied) against seeable
  // The truth's lattice (options.cell_m; row 0 at the grid's origin_y) and each cell's agreement, for a picture.
  int lattice_width = 0, lattice_height = 0;
  std::vector<CellAgreement> cells;
};

// `map_from_world` places the scene in the grid's frame; `path_world` is the
// true sensor path (world frame).
GridTruthScore score_grid(const GridView& grid, std::span<const Triangle> scene, const Eigen::Isometry3d& map_from_world,
                          std::span<const Eigen::Vector3d> path_world, const GridTruthOptions& options);

}  // namespace adit::eval
