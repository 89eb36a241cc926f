#include "adit/slam/global_localisation.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "adit/slam/registration.hpp"
#include "adit/slam/voxel_downsample.hpp"

namespace adit::slam {
namespace {

struct Peak {
  double score = 0.0;  // mean plan likelihood of the search points
  int ix = 0;
  int iy = 0;
  double yaw = 0.0;
};

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

double wrap(double a) { return std::remainder(a, 2.0 * std::numbers::pi); }

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

// Exhaustive plan-view search: every free floor cell (in the hint's disc),
// every yaw step (in its range); the best few distinct peaks.
std::vector<Peak> search_plan(std::span<const Eigen::Vector3f> walls, const PlanGrid& plan,
                              const std::optional<LocalisationHint>& hint, const LocalisationConfig& config) {
  // Search points: the walls' horizontal positions within range, spread evenly.
  std::vector<Eigen::Vector2f> flat;
  for (const auto& p : walls)
    if (p.head<2>().norm() <= config.search_range_m) flat.push_back(p.head<2>());
  if (flat.size() > config.max_search_points) {
    std::vector<Eigen::Vector2f> kept;
    const double step = static_cast<double>(flat.size()) / static_cast<double>(config.max_search_points);
    for (std::size_t k = 0; k < config.max_search_points; ++k) kept.push_back(flat[static_cast<std::size_t>(static_cast<double>(k) * step)]);
    flat.swap(kept);
  }
  // The likelihood padded by the search range, so that no lookup needs a bounds check.
  const int pad = static_cast<int>(std::ceil(config.search_range_m / plan.cell_m)) + 2;
  const int wp = plan.width + 2 * pad;
  const int hp = plan.height + 2 * pad;
  std::vector<float> field(static_cast<std::size_t>(wp) * static_cast<std::size_t>(hp), 0.0F);
  for (int iy = 0; iy < plan.height; ++iy)
    std::copy_n(plan.likelihood.begin() + static_cast<std::ptrdiff_t>(plan.index(0, iy)), plan.width,
                field.begin() + static_cast<std::ptrdiff_t>((iy + pad) * wp + pad));
  // Candidate cells: a floor, clear of walls, in the hint's disc.
  std::vector<std::int64_t> bases;
  std::vector<std::pair<int, int>> cells;
  for (int iy = 0; iy < plan.height; ++iy) {
    for (int ix = 0; ix < plan.width; ++ix) {
      const std::size_t c = plan.index(ix, iy);
      if (std::isnan(plan.floor_z[c]) || plan.wall_distance[c] < config.min_wall_clearance_m) continue;
      if (hint) {
        const Eigen::Vector2d centre(plan.origin.x() + (ix + 0.5) * plan.cell_m, plan.origin.y() + (iy + 0.5) * plan.cell_m);
        if ((centre - hint->position).norm() > hint->radius_m) continue;
      }
      bases.push_back(static_cast<std::int64_t>(iy + pad) * wp + ix + pad);
      cells.emplace_back(ix, iy);
    }
  }
  std::vector<Peak> peaks;
  if (bases.empty() || flat.empty()) return peaks;
  double yaw_lo = 0.0, yaw_span = 2.0 * std::numbers::pi;
  if (hint && hint->yaw_tolerance_rad < std::numbers::pi) {
    yaw_lo = hint->yaw_rad - hint->yaw_tolerance_rad;
    yaw_span = 2.0 * hint->yaw_tolerance_rad;
  }
  const int yaws = std::max(1, static_cast<int>(std::ceil(yaw_span / config.yaw_step_rad)));
  std::vector<std::int64_t> offsets(flat.size());
  const float inv_cell = 1.0F / plan.cell_m;
  const float inv_n = 1.0F / static_cast<float>(flat.size());
  constexpr int kPerYaw = 3;
  for (int k = 0; k < yaws; ++k) {
    const double yaw = yaw_lo + (k + 0.5) * yaw_span / yaws;
    const Eigen::Rotation2Df r(static_cast<float>(yaw));
    const Eigen::Matrix2f m = r.toRotationMatrix();
    for (std::size_t i = 0; i < flat.size(); ++i) {
      // The cell centre is the origin: a point's cell is its offset rounded.
      const Eigen::Vector2f q = m * flat[i] * inv_cell;
      offsets[i] = static_cast<std::int64_t>(std::lround(q.y())) * wp + std::lround(q.x());
    }
    std::array<Peak, kPerYaw> best{};
    for (std::size_t c = 0; c < bases.size(); ++c) {
      const float* base = field.data() + bases[c];
      float sum = 0.0F;
      for (const std::int64_t o : offsets) sum += base[o];
      const double score = sum * inv_n;
      if (score <= best[kPerYaw - 1].score) continue;
      int j = kPerYaw - 1;
      for (; j > 0 && best[static_cast<std::size_t>(j - 1)].score < score; --j) best[static_cast<std::size_t>(j)] = best[static_cast<std::size_t>(j - 1)];
      best[static_cast<std::size_t>(j)] = Peak{score, cells[c].first, cells[c].second, yaw};
    }
    for (const Peak& p : best)
      if (p.score > 0.0) peaks.push_back(p);
  }
  std::sort(peaks.begin(), peaks.end(), [](const Peak& a, const Peak& b) { return a.score > b.score; });
  // Non-maximum suppression: a peak near a better one is the same place.
  std::vector<Peak> kept;
  for (const Peak& p : peaks) {
    const bool near = std::any_of(kept.begin(), kept.end(), [&](const Peak& q) {
      const double d = plan.cell_m * std::hypot(p.ix - q.ix, p.iy - q.iy);
      return d < config.distinct_m && std::abs(wrap(p.yaw - q.yaw)) < config.distinct_rad;
    });
    if (!near) kept.push_back(p);
    if (static_cast<int>(kept.size()) == config.hypotheses) break;
  }
  return kept;
}

Refined refine(const CloudParts& parts, std::span<const Eigen::Vector3f> sparse, const Peak& peak, const PriorMap& prior,
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
  const std::vector<Peak> peaks = search_plan(parts.walls, prior.plan, hint, config);
  if (peaks.empty()) {
    result.failure = hint ? "no free floor in the prior within the hint's disc" : "the prior has no free floor to start on";
    return result;
  }
  // Registration points: the cloud thinned further (the search has placed it within a cell).
  std::vector<Eigen::Vector3f> sparse(parts.points.size());
  VoxelDownsampler downsampler(parts.points.size());
  sparse.resize(downsampler.downsample(parts.points, 2.0F * config.cloud_voxel_m, sparse));
  std::vector<Refined> refined;
  for (const Peak& peak : peaks) refined.push_back(refine(parts, sparse, peak, prior, index, config));
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
