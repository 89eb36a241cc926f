#pragma once
// Retro-reflective survey targets found in the map: a target returns far more
// light than rock or plaster, so its points stand out by intensity (the
// simulator's discs reflect 230 against walls' 10-70). Points at or above
// min_intensity are grouped by connectivity (voxels of cluster_m, 26
// neighbours); a group of at least min_points no wider than max_extent_m is a
// target. Its centre is the mean of its points (the map keeps one point per
// voxel, spread evenly over the disc); its sigma is the standard error of that
// mean, sqrt((s_plane² + v²/12) / n) with s_plane the RMS distance of the
// points to their best-fit plane and v the map's voxel (the quantisation of
// where a point sits in its voxel).

#include <filesystem>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "adit/slam/trajectory.hpp"

namespace adit::products {

struct TargetOptions {
  float min_intensity = 150.0F;
  double cluster_m = 0.10;
  int min_points = 5;
  double max_extent_m = 0.6;       // a 0.3 m disc seen from the side is still within this
  double max_path_distance_m = 30.0;
  double voxel_m = 0.05;           // the map's voxel (aditd's map.voxel_m)
};

struct FoundTarget {
  int id = 0;
  Eigen::Vector3d centre{0, 0, 0};
  double sigma_m = 0.0;
  int points = 0;
};

// Ids in order along the path (the nearest path pose's index), from 1.
std::vector<FoundTarget> find_targets(std::span<const Eigen::Vector3f> points, std::span<const float> intensities,
                                      const slam::Trajectory& sensor_path, const TargetOptions& options);

// `id,x,y,z,sigma_m` (map frame, 0.1 mm), what `adit targets find` and the
// session products write. Throws adit::InputError naming the file when it
// cannot be written.
void write_targets_csv(const std::filesystem::path& file, std::span<const FoundTarget> targets);

}  // namespace adit::products
