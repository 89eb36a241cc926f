#pragma once
// A finished session's map as the products need it: every map point with a
// place on the path it can be seen from, i.e. a ray. aditd's map keeps one
// point per voxel and, for points of tiles that were written to disk, only
// the tile's newest time (daemon/tile_spill.hpp), so a point's own stamp
// does not say where it was measured from. A ray is made instead from the
// nearest sensor position on the path (map_trajectory.tum with config.yaml's
// lidar.extrinsics, sampled every `path_step_m`) whose straight line to the
// point crosses no other mapped voxel: a line of sight in the finished map,
// which is what occupancy mapping needs (OctoMap, Hornung et al. 2013, §3);
// the nearest visible one gives short rays, crossing the drift square to the
// walls. A point with no visible position among the nearest few casts no ray.

#include <cstdint>
#include <filesystem>
#include <vector>

#include <Eigen/Geometry>

#include "adit/protocol/map_point.hpp"
#include "adit/slam/trajectory.hpp"

namespace adit::products {

struct RayOptions {
  double path_step_m = 0.25;     // sensor positions this far apart along the path
  double voxel_m = 0.10;         // the line-of-sight test's voxels
  double end_clearance_m = 0.30; // voxels this close to the point do not block (its own surface)
  int candidates = 12;           // nearest path positions tried, nearest first
  double max_range_m = 40.0;     // farther positions are not tried (aditd's map.max_range_m)
};

struct SessionMap {
  std::vector<Eigen::Vector3f> points;   // map frame, m
  std::vector<float> intensities;        // sensor units (0 when the map has none)
  std::vector<std::int32_t> origin;      // index into `viewpoints`, -1: no line of sight found
  std::vector<Eigen::Vector3f> viewpoints;  // the sensor on the path, every path_step_m
  slam::Trajectory sensor_path;          // the sensor's poses in the map frame (drawing, cross-sections)
  std::size_t without_ray = 0;
};

// Rays from map points to the path of the body poses; the sensor sits at
// `body_to_sensor` in the body frame.
SessionMap rays_from(const std::vector<protocol::MapPoint>& points, const slam::Trajectory& body_poses,
                     const Eigen::Isometry3d& body_to_sensor, const RayOptions& options);

// What a session folder holds for the products: the map's points, the body
// poses (map_trajectory.tum) and the LiDAR's place on the body (config.yaml's
// lidar.extrinsics; identity without a config).
struct SessionInputs {
  std::vector<protocol::MapPoint> points;
  slam::Trajectory body_poses;
  Eigen::Isometry3d body_to_sensor = Eigen::Isometry3d::Identity();
  std::size_t read_points = 0;  // in the map file
  double thin_voxel_m = 0.0;    // the voxel `points` were thinned to (0: not thinned)
  std::size_t thinned = 0;      // points of the file left out by the thinning
};

// Reads the map file, map_trajectory.tum and config.yaml. Missing or bad
// files throw adit::InputError naming the file. The map is thinned as it is
// read to its first point per voxel of `thin_voxel_m` (map_thinning.hpp):
// < 0 the session's own map.voxel_m (none without config.yaml), 0 every point.
// Only the kept points are held: the 30-minute drive's map file of 14.7 M
// points was 1.1 GB of memory read whole, 0.17-0.25 GB thinned as read.
SessionInputs read_session_inputs(const std::filesystem::path& session_dir, double thin_voxel_m = 0.0);

// The session's map file: SESSION_DIR/map.las, .ply or .pcd (the first there).
std::filesystem::path map_file_of(const std::filesystem::path& session_dir);

// Reads the map file, map_trajectory.tum and config.yaml. Missing or bad
// files throw adit::InputError naming the file.
SessionMap read_session_map(const std::filesystem::path& session_dir, const RayOptions& options);

}  // namespace adit::products
