#include "adit/slam/global_localisation.hpp"

#include <algorithm>
#include <limits>
#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "adit/slam/plan_search.hpp"
#include "adit/slam/registration.hpp"
#include "adit/slam/voxel_downsample.hpp"

namespace adit::slam {
namespace {

struct Refined {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Identity();
  double overlap = 0.0;
  bool degenerate = false;
  double weakest = 0.0;
};

double angle_between(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

// The cloud split by its local planes: vertical surfaces, and the floor's height below the origin.
struct CloudParts {
  std::vector<Eigen::Vector3f> points;  // downsampled
  std::vector<Eigen::Vector3f> walls;
  float floor_z = std::numeric_limits<float>::quiet_NaN();
};

CloudParts split_cloud(std::span<const Eigen::Vector3f> cloud, const LocalisationConfig& config) {
  CloudParts parts;
  VoxelDownsampler downsampler(cloud.size());
  parts.points.resize(cloud.size());
  parts.points.resize(downsampler.downsample(cloud, config.cloud_voxel_m, parts.points));
  const float voxel = 3.0F * config.cloud_voxel_m;
  VoxelHashMap local(voxel, std::max<std::size_t>(1024, 2 * parts.points.size()));
  local.add(parts.points);
  std::vector<float> floor;
  for (const auto& p : parts.points) {
    const MapPlane plane = local.nearest_plane(p, 8, 0.1F);
    if (!plane.found) continue;
    const float nz = std::abs(plane.normal.z());
    if (nz < 0.3F) parts.walls.push_back(p);
    else if (nz > 0.9F && p.z() < -0.3F) floor.push_back(p.z());
  }
  if (floor.size() >= 20) {
    // The lowest large horizontal surface: the 10th percentile of the downward points' heights.
    std::nth_element(floor.begin(), floor.begin() + static_cast<std::ptrdiff_t>(floor.size() / 10), floor.end());
    parts.floor_z = floor[floor.size() / 10];
  }
  return parts;
}

// Share of `walls` (moved by `pose`) within overlap_m of a prior point.
double overlap_of(std::span<const Eigen::Vector3f> walls, const Eigen::Isometry3d& pose, const VoxelHashMap& index,
                  double overlap_m) {
  if (walls.empty()) return 0.0;
  const Eigen::Isometry3f t = pose.cast<float>();
  std::size_t inliers = 0;
  for (const auto& p : walls) {
    const Eigen::Vector3f q = t * p;
    if (index.nearest(q, static_cast<float>(overlap_m)).found) ++inliers;
  }
  return static_cast<double>(inliers) / static_cast<double>(walls.size());
}

Refined refine(const CloudParts& parts, std::span<const Eigen::Vector3f> sparse, const PlanPeak& peak, const PriorMap& prior,
               const VoxelHashMap& index, const LocalisationConfig& config) {
  const PlanGrid& plan = prior.plan;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(peak.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(plan.origin.x() + (peak.ix + 0.5) * plan.cell_m,
                                       plan.origin.y() + (peak.iy + 0.5) * plan.cell_m,
                                       plan.floor_z[plan.index(peak.ix, peak.iy)] - parts.floor_z);
  PosePrior prior_pose;
  RegistrationConfig registration;
  registration.max_iterations = 40;
  registration.point_sigma_m = config.point_sigma_m;
  Refined out;
  RegistrationResult last;
  // Coarse to fine: the search is within a plan cell and a yaw step; the
  // height from the floors within a few centimetres.
  for (const auto& [max_distance, kernel] : {std::pair{1.0, 0.3}, std::pair{0.4, 0.1}, std::pair{0.2, 0.05}}) {
    prior_pose.mean = pose;
    // Gravity holds roll and pitch loosely (the cloud is levelled to a degree or so).
    prior_pose.gravity.up_body = Eigen::Vector3d::UnitZ();
    prior_pose.gravity.information = 1.0 / (0.05 * 0.05);
    const RegistrationResult r = register_scan(sparse, index, prior_pose, max_distance, kernel, registration);
    last = r;
    pose = r.pose;
    out.covariance = r.covariance;
    out.degenerate = r.degenerate;
  }
  out.pose = pose;
  out.overlap = overlap_of(parts.walls, pose, index, config.overlap_m);
  out.weakest = last.weakest_eigenvalue;
  return out;
}

}  // namespace

Eigen::Isometry3d levelled_frame_at(const Eigen::Vector3d& up, const Eigen::Vector3d& origin) {
  Eigen::Isometry3d level = Eigen::Isometry3d::Identity();
  level.linear() = Eigen::Quaterniond::FromTwoVectors(up, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  level.translation() = -(level.linear() * origin);
  return level;
}

LocalisationResult localise(std::span<const Eigen::Vector3f> cloud, const PriorMap& prior, const VoxelHashMap& index,
                            const std::optional<LocalisationHint>& hint, const LocalisationConfig& config) {
  LocalisationResult result;
  const CloudParts parts = split_cloud(cloud, config);
  result.wall_points = parts.walls.size();
  if (static_cast<int>(parts.walls.size()) < config.min_wall_points) {
    result.failure = fmt::format("too little seen: {} wall points (at least {})", parts.walls.size(), config.min_wall_points);
    return result;
  }
  if (std::isnan(parts.floor_z)) {
    result.failure = "no floor seen below the sensor: the height cannot be started";
    return result;
  }
  const std::vector<PlanPeak> peaks = search_plan(parts.walls, prior.plan, hint, config).peaks;
  if (peaks.empty()) {
    result.failure = hint ? "no free floor in the prior within the hint's disc" : "the prior has no free floor to start on";
    return result;
  }
  // Registration points: the cloud thinned further (the search has placed it within a cell).
  std::vector<Eigen::Vector3f> sparse(parts.points.size());
  VoxelDownsampler downsampler(parts.points.size());
  sparse.resize(downsampler.downsample(parts.points, 2.0F * config.cloud_voxel_m, sparse));
  std::vector<Refined> refined;
  for (const PlanPeak& peak : peaks) refined.push_back(refine(parts, sparse, peak, prior, index, config));
  result.hypotheses_refined = static_cast<int>(refined.size());
  std::sort(refined.begin(), refined.end(), [](const Refined& a, const Refined& b) { return a.overlap > b.overlap; });
  const Refined& best = refined.front();
  result.pose = best.pose;
  result.covariance = best.covariance;
  result.overlap = best.overlap;
  result.weakest_eigenvalue = best.weakest;
  for (std::size_t k = 1; k < refined.size(); ++k) {
    const double d = (refined[k].pose.translation() - best.pose.translation()).norm();
    if (d > config.rival_m || angle_between(refined[k].pose, best.pose) > config.rival_rad) {
      result.rival_overlap = refined[k].overlap;
      result.rival_distance_m = d;
      break;
    }
  }
  const double position_sigma = std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(best.covariance.topLeftCorner<3, 3>()).eigenvalues().maxCoeff());
  const double yaw_sigma = std::sqrt(best.covariance(5, 5));
  result.position_sigma_m = position_sigma;
  result.yaw_sigma_rad = yaw_sigma;
  if (best.overlap < config.min_overlap) {
    result.failure = fmt::format("overlap {:.2f} below {:.2f}: the prior does not match what is seen here "
                                 "(another building, a start outside the prior, or wrong units or axes)",
                                 best.overlap, config.min_overlap);
  } else if (1.0 - result.rival_overlap < config.min_rival_miss_ratio * (1.0 - best.overlap)) {
    result.failure = fmt::format("ambiguous: a pose {:.1f} m away leaves nearly as few points unexplained (overlap "
                                 "{:.2f} against {:.2f})",
                                 result.rival_distance_m, result.rival_overlap, best.overlap);
  } else if (best.degenerate || best.weakest < config.min_weakest_eigenvalue) {
    result.failure = fmt::format("ill-conditioned: the registration's weakest direction has {:.3f} (at least {:.3f}): "
                                 "too little fixes it here (a long corridor?)",
                                 best.weakest, config.min_weakest_eigenvalue);
  } else if (position_sigma > config.max_position_sigma_m || yaw_sigma > config.max_yaw_sigma_rad) {
    result.failure = fmt::format("uncertain: σ {:.3f} m, {:.2f}° (limits {:.3f} m, {:.2f}°)", position_sigma,
                                 yaw_sigma * 180.0 / std::numbers::pi, config.max_position_sigma_m,
                                 config.max_yaw_sigma_rad * 180.0 / std::numbers::pi);
  } else {
    result.success = true;
  }
  return result;
}

}  // namespace adit::slam
