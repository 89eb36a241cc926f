// The floor under a ground robot's LiDAR (ground_plane.hpp).

#include "adit/eval/ground_plane.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>

namespace adit::eval {
namespace {

// The least-squares plane through `points` (the centroid, and the scatter's
// smallest eigenvector), its normal turned towards `up`.
GroundPlane fit_plane(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) scatter += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
  GroundPlane g;
  g.normal = eigen.eigenvectors().col(0);
  if (g.normal.dot(up) < 0.0) g.normal = -g.normal;
  g.height = g.normal.dot(Eigen::Vector3d::Zero() - mean);  // the sensor (origin) above the plane
  g.inliers = points.size();
  return g;
}

double median_of(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

std::optional<GroundPlane> find_ground(std::span<const Eigen::Vector3f> points, const Eigen::Vector3d& up_in,
                                       const GroundOptions& o) {
  const Eigen::Vector3d up = up_in.normalized();
  std::vector<Eigen::Vector3d> candidates;
  candidates.reserve(points.size() / 4);
  for (const Eigen::Vector3f& pf : points) {
    const Eigen::Vector3d p = pf.cast<double>();
    const double range = p.norm();
    if (!std::isfinite(range) || range < o.min_range || range > o.max_range) continue;
    if (p.dot(up) > -o.min_below) continue;
    candidates.push_back(p);
  }
  if (candidates.size() < std::max<std::size_t>(o.min_inliers, 3)) return std::nullopt;

  std::mt19937_64 rng(o.seed);
  std::uniform_int_distribution<std::size_t> pick(0, candidates.size() - 1);
  const double cos_tilt = std::cos(o.max_tilt);
  std::size_t best_count = 0;
  Eigen::Vector3d best_normal = up;
  double best_offset = 0.0;
  for (unsigned k = 0; k < o.iterations; ++k) {
    const Eigen::Vector3d& a = candidates[pick(rng)];
    const Eigen::Vector3d& b = candidates[pick(rng)];
    const Eigen::Vector3d& c = candidates[pick(rng)];
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() < 1e-6) continue;
    n.normalize();
    if (n.dot(up) < 0.0) n = -n;
    if (n.dot(up) < cos_tilt) continue;
    const double offset = -n.dot(a);  // n·p + offset = 0 on the plane
    std::size_t count = 0;
    for (const Eigen::Vector3d& p : candidates) count += std::abs(n.dot(p) + offset) < o.inlier_distance ? 1 : 0;
    if (count > best_count) {
      best_count = count;
      best_normal = n;
      best_offset = offset;
    }
  }
  if (best_count < o.min_inliers) return std::nullopt;
  // Refined twice on the inliers of the plane so far.
  GroundPlane g;
  for (int round = 0; round < 2; ++round) {
    std::vector<Eigen::Vector3d> inliers;
    for (const Eigen::Vector3d& p : candidates)
      if (std::abs(best_normal.dot(p) + best_offset) < o.inlier_distance) inliers.push_back(p);
    if (inliers.size() < o.min_inliers) return std::nullopt;
    g = fit_plane(inliers, up);
    best_normal = g.normal;
    best_offset = g.height;
  }
  if (g.normal.dot(up) < cos_tilt) return std::nullopt;
  return g;
}

std::optional<GroundSummary> combine_ground(std::span<const GroundPlane> planes) {
  if (planes.empty()) return std::nullopt;
  // The median normal (componentwise, normalised), then the angles from it.
  std::vector<double> x, y, z;
  for (const GroundPlane& p : planes) {
    x.push_back(p.normal.x());
    y.push_back(p.normal.y());
    z.push_back(p.normal.z());
  }
  const Eigen::Vector3d centre = Eigen::Vector3d(median_of(x), median_of(y), median_of(z)).normalized();
  std::vector<double> angles;
  for (const GroundPlane& p : planes) angles.push_back(std::acos(std::clamp(p.normal.dot(centre), -1.0, 1.0)));
  // Angles from the centre are positive (a Rayleigh-like spread): judge them
  // against 3 times their median, about 3.5 sigma of one axis.
  const double limit = std::max(3.0 * median_of(angles), 1e-6);
  GroundSummary s;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::vector<double> heights;
  double angle_sq = 0.0;
  for (std::size_t i = 0; i < planes.size(); ++i) {
    if (angles[i] > limit) {
      ++s.outliers;
      continue;
    }
    sum += planes[i].normal;
    heights.push_back(planes[i].height);
    angle_sq += angles[i] * angles[i];
    ++s.scans;
  }
  s.normal = sum.normalized();
  const double n = static_cast<double>(s.scans);
  // Each scan's normal scatters by sigma per axis across it (angle^2 sums two axes).
  s.angle_sd = std::sqrt(angle_sq / std::max(1.0, 2.0 * n - 2.0)) / std::sqrt(n);
  s.height = median_of(heights);
  std::vector<double> spread;
  for (const double h : heights) spread.push_back(std::abs(h - s.height));
  s.height_sd = 1.4826 * median_of(spread);
  return s;
}

}  // namespace adit::eval
