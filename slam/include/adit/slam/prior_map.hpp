#pragma once
// A prior map (a building's BIM model, a mine's design or last month's survey)
// prepared for global localisation and for deviations: the surface points
// downsampled, each with its local plane's normal, and a plan view of it.
//
// The plan view is what the global search correlates against (a correlative
// scan matcher, Olson, ICRA 2009; Hess et al., ICRA 2016): buildings and mine
// drifts are 2.5-D, their vertical surfaces (walls, pillars, ribs) seen from
// above form a floor plan, and gravity (the accelerometer) fixes roll and
// pitch, so a start pose is found by an exhaustive search over x, y and yaw
// (docs/PRIOR-MAP.md, docs/decisions/026-prior-map-correlative-search.md).
//
// Frames: the prior's own (site or local), z up, metres.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "adit/slam/voxel_hash_map.hpp"

namespace adit::slam {

struct PriorMapConfig {
  float point_spacing_m = 0.1F;     // downsampling voxel of the prior's points
  float normal_radius_m = 0.35F;    // voxel of the index the normals' neighbours are searched in
  int normal_neighbors = 7;         // points a normal's plane is fitted through: few, so both faces of a 0.2 m partition are not mixed
  float plan_cell_m = 0.25F;        // plan-view cell (the coarse search's translation step)
  float plan_sigma_m = 0.25F;       // width of the plan's likelihood field round a wall
  float vertical_max_nz = 0.3F;     // |n_z| below this: a vertical surface (wall, pillar)
  float horizontal_min_nz = 0.9F;   // |n_z| above this: floor or ceiling
};

// A plan-view grid, row-major (x fastest), cell (0, 0) centred on origin + cell/2.
struct PlanGrid {
  Eigen::Vector2f origin = Eigen::Vector2f::Zero();
  float cell_m = 0.25F;
  int width = 0;
  int height = 0;
  // exp(-d²/2σ²), d the distance from the cell centre to the nearest cell
  // holding a vertical surface (0 beyond 3σ).
  std::vector<float> likelihood;
  // The lowest floor (upward-facing horizontal surface) in the cell, NaN where
  // there is none: where a platform can stand, and at what height.
  std::vector<float> floor_z;
  // Distance to the nearest vertical-surface cell, m (capped at 2 m).
  std::vector<float> wall_distance;

  bool contains(int ix, int iy) const { return ix >= 0 && iy >= 0 && ix < width && iy < height; }
  std::size_t index(int ix, int iy) const {
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(width) + static_cast<std::size_t>(ix);
  }
};

struct PriorMap {
  float point_spacing_m = 0.1F;
  std::vector<Eigen::Vector3f> points;   // downsampled surface points
  std::vector<Eigen::Vector3f> normals;  // unit, per point; zero where no plane fits (edges, clutter)
  PlanGrid plan;
  // How the normals split: a building or mine prior has plenty of both; a
  // prior whose "horizontal" share is tiny and whose y-normals dominate was
  // exported Y-up (checked by check_prior_map).
  std::size_t vertical_points = 0;
  std::size_t horizontal_points = 0;
};

// Downsamples, fits normals and draws the plan. `points` in metres, z up.
// Throws std::invalid_argument when there are no finite points.
PriorMap prepare_prior_map(std::span<const Eigen::Vector3f> points, const PriorMapConfig& config = {});

// An empty string when the prior looks like a z-up metric map of a site; else
// why not (a 20 km extent: millimetres read as metres; no floor but many
// y-facing planes: exported Y-up; no vertical surfaces: nothing to localise on).
std::string check_prior_map(const PriorMap& prior);

// The prior's points in a voxel hash (the index registration and the
// deviations search), sized for them.
VoxelHashMap index_prior_map(const PriorMap& prior, float voxel_m = 0.5F);

}  // namespace adit::slam
