#pragma once
// Refines each mapped scan's pose against a dense map of the scans refined
// before it, in the mapping thread (scan-to-map as in LOAM's mapping step,
// Zhang & Singh 2014, which re-registers the odometry's scans against a finer
// map at a lower rate).
//
// Why (docs/decisions/013-map-refinement.md): with wheels, the odometry's
// registration weighs each point as σ 1 m (RegistrationConfig::point_sigma_m)
// so that a self-similar drift cannot overrule the wheels, and its local map
// holds the scans at 0.25 m. Along a mine drive the wheels then set the
// travel: a wheel radius 0.4 % off (the simulator's default) put the 60 s
// drive 9 cm behind the truth after 25 m, and the map lost 11 points of 100
// within 5 cm to that alone. Against a map that keeps the rough walls at
// 0.1 m, the scan itself tells the travel: the same drive's poses come to
// 2.3 cm rms.
//
// The prior is the odometry's motion since the previous scan, applied to the
// previous refined pose, with σ 0.05 m and 0.2 rad per scan: loose enough for
// the scan to correct a few mm of travel per scan, tight enough to keep a
// featureless drift's axis (where the scan is biased towards "no motion") and
// a moment of poor overlap near the odometry's motion.
//
// Pure and single-threaded; buffers are sized at construction, so refine()
// does not allocate (the mapping thread may, but need not).

#include <cstddef>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "adit/slam/map_insertion.hpp"
#include "adit/slam/registration.hpp"
#include "adit/slam/voxel_downsample.hpp"
#include "adit/slam/voxel_hash_map.hpp"

namespace adit::slam {

struct MapRefinerConfig {
  float map_voxel_m = 0.5F;           // the refinement map's voxel (planes are fitted within one voxel edge)
  float map_point_spacing_m = 0.05F;  // between a voxel's points (VoxelHashMap's spacing)
  float map_points_m = 0.1F;          // each refined scan enters the map downsampled at this
  float source_voxel_m = 0.25F;       // the scan is registered downsampled at this
  std::size_t map_capacity_voxels = std::size_t{1} << 17;
  float map_radius_m = 50.0F;         // the map forgets what lies farther from the sensor
  double prior_sigma_m = 0.05;        // of the odometry's motion since the previous scan, per scan
  double prior_sigma_rad = 0.2;        // about the body's z axis (yaw)
  double prior_sigma_tilt_rad = 0.002;  // about its x and y axes (roll, pitch)
  double max_distance_m = 0.5;        // correspondences
  double kernel_scale_m = 0.1;        // the robust kernel's starting scale
  std::size_t max_scan_points = 400'000;
  RegistrationConfig registration;
  MapInsertionStep map_insertion;      // a refined scan enters the map once the body has moved
};

class MapRefiner {
 public:
  explicit MapRefiner(const MapRefinerConfig& config = {});

  // `odometry_pose`: the scan's pose from odometry; `points`: the scan in the
  // body frame at that pose, deskewed. Returns the refined pose (the first
  // scan keeps its odometry pose: it defines the map frame) and adds the
  // scan, placed there, to the refinement map once the body has moved since
  // the last scan it took (map_insertion). `inertial`: the pose comes from
  // the LiDAR-inertial odometry; then a scan from where the map last took
  // one is not registered but keeps the odometry's motion: at rest the
  // registration against a map of that one view creeps (0.18° over a
  // hand-held's 2 s start), where the gyroscope holds the attitude
  // (docs/decisions/034-refinement-holds-at-rest.md).
  Eigen::Isometry3d refine(const Eigen::Isometry3d& odometry_pose, std::span<const Eigen::Vector3f> points,
                           bool inertial = false);

  // The last registration (zero iterations for the first scan).
  const RegistrationResult& last() const { return last_; }
  const VoxelHashMap& map() const { return map_; }

 private:
  MapRefinerConfig config_;
  VoxelHashMap map_;
  VoxelDownsampler downsampler_;
  std::vector<Eigen::Vector3f> source_;
  std::vector<Eigen::Vector3f> placed_;
  std::vector<MapPlane> planes_;
  Eigen::Isometry3d last_odometry_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d last_refined_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d added_at_ = Eigen::Isometry3d::Identity();  // where the map last took a scan
  RegistrationResult last_;
  bool started_ = false;
};

}  // namespace adit::slam
