#pragma once
// The products of a finished session, made from its folder (map.las/.ply/.pcd,
// map_trajectory.tum, config.yaml): the 3D occupancy
// (.bt, .ot), the 2D occupancy grid (PGM + YAML), and their figures in
// products.json (and in summary.json's "products" when there is one). aditd
// calls write_session_products() after a session has stopped, from a thread
// of its own (the next session may start meanwhile); `adit products` calls
// it for any session folder. docs/PRODUCTS.md says how each step works.

#include <atomic>
#include <cstdint>
#include <stdexcept>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "adit/products/cross_sections.hpp"
#include "adit/products/ground.hpp"
#include "adit/products/moving_objects.hpp"
#include "adit/products/occupancy_3d.hpp"
#include "adit/products/outlier_filter.hpp"
#include "adit/products/session_map.hpp"
#include "adit/products/target_finder.hpp"
#include "adit/products/top_view.hpp"

namespace adit::products {

struct ProductsOptions {
  // The map is thinned to one point per voxel of this edge first (map_thinning.hpp):
  // < 0, the session's own map.voxel_m (config.yaml; none without one); 0, every point kept.
  double thin_voxel_m = -1.0;
  SeeThroughOptions moving;         // moving objects out of the map (moving_objects.hpp); moving.enabled
  RayOptions rays;
  Occupancy3dOptions occupancy;
  GroundOptions ground;
  OutlierOptions outliers;
  double grid_resolution_m = 0.05;  // the 2D grid's cells; 0.01 .. 1
  double band_low_m = 0.15;         // heights above the ground that block a robot / count as its free space
  double band_high_m = 2.0;
  bool write_ot = false;            // the full-probability octree beside the .bt
  bool line_of_sight_fill = true;   // fill_line_of_sight (grid_projection.hpp)
  double fill_range_m = 40.0;       // aditd's map.max_range_m
  double fill_step_m = 0.25;        // every viewpoint of the path (RayOptions::path_step_m); 1 m before 2026-12-01
  TopViewOptions top_view;
  SectionOptions sections;
  TargetOptions targets;            // targets.csv, drawn on the top view
  // Set from another thread to stop early (aditd's shutdown): checked between
  // the steps and every octree batch; the rays to the path (read_session_map)
  // run to their end first. Null: never.
  const std::atomic<bool>* cancel = nullptr;
};

// Thrown by write_session_products() when `cancel` was set; nothing more is written.
struct Cancelled : std::runtime_error {
  Cancelled() : std::runtime_error("cancelled") {}
};

struct ProductsReport {
  std::size_t read_points = 0;      // in the session's map file
  double thin_voxel_m = 0.0;        // the voxel the map was thinned to (0: not thinned)
  std::size_t thinned = 0;          // of read_points, more than one in a voxel: dropped
  std::size_t points = 0;           // after the moving objects were removed
  std::size_t moving_removed = 0;   // map points of moving objects taken out
  std::size_t moving_candidates = 0, moving_suspects = 0, moving_scans = 0;
  double moving_cpu_s = 0.0;        // of cpu_s, the moving objects' pass (decoding the recording included)
  std::string moving_skipped;       // why the moving objects were not removed (empty: they were)
  std::uintmax_t map_static_bytes = 0;  // map_static.<ext>: the map without them
  std::string map_static_file;      // its name, empty when the removal did not run
  std::size_t without_ray = 0;  // no line of sight to the path found: occupied, casting no free space
  std::size_t ground_points = 0;
  std::size_t outliers_removed = 0;
  std::size_t leaves = 0;
  std::size_t grid_occupied = 0, grid_free = 0, grid_unknown = 0;
  std::size_t grid_filled = 0;  // of the free cells, those the line-of-sight fill made free
  std::string points_file;          // the session's map file (map.las, .ply or .pcd)
  std::uintmax_t points_bytes = 0;
  std::uintmax_t bt_bytes = 0;
  std::uintmax_t ot_bytes = 0;
  std::uintmax_t grid_bytes = 0;    // PGM + YAML
  std::uintmax_t top_view_bytes = 0;
  std::size_t sections = 0, sections_measured = 0;  // measured: width and height both found
  std::size_t sections_moved = 0;         // stations moved to where the walls run on
  std::size_t sections_walls_broken = 0;  // stations with no such place within reach (no width)
  std::size_t targets = 0;          // found by intensity (targets.csv)
  std::string targets_note;         // why none were looked for ("" when they were)
  double cpu_s = 0.0;               // this thread's CPU time for all of it
  std::vector<std::pair<std::string, double>> cpu_by_step;  // of cpu_s, each step's, in order (s)
  std::filesystem::path out_dir;
};

// Checks the options; throws adit::InputError naming the option.
void check_options(const ProductsOptions& options);

// Takes moving objects out of the map first (when options.moving.enabled and
// the session has its raw recording) and writes the rest as
// OUT_DIR/map_static.<the map's extension>, the removed points as
// OUT_DIR/moving_points.ply. Writes OUT_DIR/occupancy.bt (and .ot), grid.pgm, grid.yaml, top_view.png,
// sections/section_NNN.svg and sections/sections.csv, targets.csv (when the
// map has intensities; else the report says so and the rest is written), products.json;
// OUT_DIR defaults to SESSION_DIR/products. Adds "products" to
// SESSION_DIR/summary.json when it exists (written to a temporary file and
// renamed). Throws adit::InputError for a missing or bad session file.
ProductsReport write_session_products(const std::filesystem::path& session_dir, const ProductsOptions& options,
                                      const std::filesystem::path& out_dir = {});

}  // namespace adit::products
