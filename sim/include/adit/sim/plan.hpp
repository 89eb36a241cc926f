#pragma once
// The floor plan of an underground scene: drifts (straight segments with a
// width) and chambers (discs), with a roof height field. Its signed distance
// (negative inside the open space) decides where rock is; plan_mesh.hpp turns
// it into walls, floor and roof.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace adit::sim {

struct Drift {
  Eigen::Vector2d a, b;
  double width_m = 4.0;
};

struct Chamber {
  Eigen::Vector2d centre;
  double radius_m = 8.0;
  double roof_m = 8.0;  // at the centre, falling to the drift roof at the edge
};

// An axis-aligned rectangle: open (a room) or solid (a pillar, in `pillars`).
struct Box2 {
  Eigen::Vector2d lo, hi;
  double distance(const Eigen::Vector2d& p) const;  // signed, < 0 inside
};

struct Plan {
  std::vector<Drift> drifts;
  std::vector<Chamber> chambers;
  std::vector<Box2> rooms;    // open
  std::vector<Box2> pillars;  // solid, cut out of the open space
  double roof_m = 4.5;            // drift roof height above the floor
  double roof_variation_m = 0.5;  // ± along the drifts (smooth)
  double roughness_m = 0.1;       // amplitude of the largest rock bumps (dm); finer octaves add cm
  std::uint8_t wall_reflectivity = 25;
  double cell_m = 0.25;  // marching-squares grid: finer for buildings' straight walls
  std::uint64_t seed = 0;

  // Signed distance to the open space's boundary in plan, metres (< 0 inside).
  double distance(const Eigen::Vector2d& p) const;
  double roof(const Eigen::Vector2d& p) const;
  // Rock roughness displacement (metres) at a point of the surface.
  double roughness(const Eigen::Vector3d& p) const;
};

}  // namespace adit::sim
