#include "adit/slam/map_refiner.hpp"

namespace adit::slam {

MapRefiner::MapRefiner(const MapRefinerConfig& config)
    : config_(config),
      // The mapping thread may fault pages in; the refiner's map fills about half its table on a mine drive.
      map_(config.map_voxel_m, config.map_capacity_voxels, config.map_point_spacing_m,
           VoxelHashMap::Storage::on_first_use),
      downsampler_(config.max_scan_points),
      planes_(config.max_scan_points) {
  source_.reserve(config.max_scan_points);
  placed_.reserve(config.max_scan_points);
}

Eigen::Isometry3d MapRefiner::refine(const Eigen::Isometry3d& odometry_pose, std::span<const Eigen::Vector3f> points,
                                     bool inertial) {
  const std::span<const Eigen::Vector3f> scan = points.first(std::min(points.size(), config_.max_scan_points));
  Eigen::Isometry3d refined = odometry_pose;
  last_ = RegistrationResult{};
  last_.pose = refined;
  if (started_ && !map_.empty()) {
    // The odometry's motion since the previous scan, continued from where the
    // previous scan was refined to: the odometry frame and the map frame part
    // by its drift, and only its motion is trusted.
    PosePrior prior;
    prior.mean = last_refined_ * last_odometry_.inverse() * odometry_pose;
    Vector6d information;
    information.head<3>().setConstant(1.0 / (config_.prior_sigma_m * config_.prior_sigma_m));
    information.tail<3>().setConstant(1.0 / (config_.prior_sigma_rad * config_.prior_sigma_rad));
    information(3) = information(4) = 1.0 / (config_.prior_sigma_tilt_rad * config_.prior_sigma_tilt_rad);
    prior.information = information.asDiagonal();
    const bool held_at_rest = inertial && !moved_since(added_at_, prior.mean, config_.map_insertion);
    if (!held_at_rest) downsampler_.downsample(scan, config_.source_voxel_m, source_);
    if (!held_at_rest && source_.size() >= static_cast<std::size_t>(config_.registration.min_plane_correspondences)) {
      last_ = register_scan(source_, map_, prior, config_.max_distance_m, config_.kernel_scale_m, config_.registration,
                            planes_);
      refined = last_.pose;
    } else {
      refined = prior.mean;
      last_.pose = refined;
    }
  }
  last_odometry_ = odometry_pose;
  last_refined_ = refined;
  const bool first = !started_;
  started_ = true;
  if (!first && !moved_since(added_at_, refined, config_.map_insertion)) return refined;
  added_at_ = refined;

  downsampler_.downsample(scan, config_.map_points_m, placed_);
  const Eigen::Isometry3f pose = refined.cast<float>();
  for (Eigen::Vector3f& p : placed_) p = pose * p;
  map_.add(placed_);
  map_.remove_far(pose.translation(), config_.map_radius_m);
  return refined;
}

}  // namespace adit::slam
