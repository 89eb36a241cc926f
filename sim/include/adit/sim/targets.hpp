#pragma once
// Surveyed targets on the walls, like total-station prisms or retro-reflective
// sheets: their true coordinates go to targets.csv (`id,x,y,z`, what
// `adit eval targets` reads) and the LiDAR sees them bright.

#include <cstdint>
#include <filesystem>
#include <vector>

#include <Eigen/Core>

#include "adit/sim/ray_caster.hpp"
#include "adit/sim/scene.hpp"

namespace adit::sim {

struct Target {
  int id = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

inline constexpr double kTargetRadius = 0.15;  // retro-reflective disc, metres
inline constexpr double kTargetHeight = 1.5;   // above the floor

// `count` targets spread along the route, alternately on the left and right
// wall, at the wall surface (found by casting from the route sideways).
std::vector<Target> place_targets(const Scene& scene, const RayCaster& caster, int count);
// Throws adit::InputError when the file cannot be written.
void write_targets_csv(const std::filesystem::path& file, const std::vector<Target>& targets);

}  // namespace adit::sim
