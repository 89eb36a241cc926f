#include "adit/products/ground.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include <Eigen/Eigenvalues>

namespace adit::products {
namespace {

// Least-squares plane through points (PCA: the normal is the eigenvector of
// the smallest eigenvalue of the covariance); nullopt-like flag when degenerate.
bool fit_plane(const std::vector<Eigen::Vector3d>& pts, Eigen::Vector3d& normal, Eigen::Vector3d& centroid) {
  if (pts.size() < 5) return false;
  centroid.setZero();
  for (const Eigen::Vector3d& p : pts) centroid += p;
  centroid /= static_cast<double>(pts.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : pts) cov += (p - centroid) * (p - centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  normal = eig.eigenvectors().col(0);
  if (normal.z() < 0) normal = -normal;
  return std::isfinite(normal.z());
}

}  // namespace

GroundModel::GroundModel(Eigen::Vector2d origin, double patch_m, int nx, int ny, std::vector<Eigen::Vector3d> planes,
                         std::vector<std::uint8_t> fitted)
    : origin_(origin), patch_m_(patch_m), nx_(nx), ny_(ny), planes_(std::move(planes)), fitted_(std::move(fitted)) {}

double GroundModel::height_at(double x, double y) const {
  if (planes_.empty()) return 0.0;
  const int i = std::clamp(static_cast<int>(std::floor((x - origin_.x()) / patch_m_)), 0, nx_ - 1);
  const int j = std::clamp(static_cast<int>(std::floor((y - origin_.y()) / patch_m_)), 0, ny_ - 1);
  const Eigen::Vector3d& p = planes_[static_cast<std::size_t>(j) * nx_ + i];
  return p.x() * x + p.y() * y + p.z();
}

int GroundModel::fitted_patches() const { return static_cast<int>(std::count(fitted_.begin(), fitted_.end(), 1)); }

GroundSegmentation segment_ground(std::span<const Eigen::Vector3f> points, const GroundOptions& o) {
  GroundSegmentation out;
  out.is_ground.assign(points.size(), 0);
  if (points.empty()) return out;
  Eigen::Vector2d lo(std::numeric_limits<double>::max(), std::numeric_limits<double>::max());
  Eigen::Vector2d hi = -lo;
  for (const Eigen::Vector3f& p : points) {
    lo = lo.cwiseMin(p.head<2>().cast<double>());
    hi = hi.cwiseMax(p.head<2>().cast<double>());
  }
  const int nx = static_cast<int>(std::floor((hi.x() - lo.x()) / o.patch_m)) + 1;
  const int ny = static_cast<int>(std::floor((hi.y() - lo.y()) / o.patch_m)) + 1;
  const std::size_t n_patches = static_cast<std::size_t>(nx) * ny;
  const auto patch_of = [&](const Eigen::Vector3f& p) {
    const int i = std::clamp(static_cast<int>(std::floor((p.x() - lo.x()) / o.patch_m)), 0, nx - 1);
    const int j = std::clamp(static_cast<int>(std::floor((p.y() - lo.y()) / o.patch_m)), 0, ny - 1);
    return static_cast<std::size_t>(j) * nx + i;
  };
  // Points by patch (counting sort).
  std::vector<std::size_t> start(n_patches + 1, 0);
  for (const Eigen::Vector3f& p : points) ++start[patch_of(p) + 1];
  for (std::size_t k = 0; k < n_patches; ++k) start[k + 1] += start[k];
  std::vector<std::size_t> order(points.size());
  {
    std::vector<std::size_t> next(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < points.size(); ++i) order[next[patch_of(points[i])]++] = i;
  }
  std::vector<Eigen::Vector3d> planes(n_patches, Eigen::Vector3d::Zero());
  std::vector<std::uint8_t> fitted(n_patches, 0);
  const double min_nz = std::cos(o.max_slope_deg * M_PI / 180.0);
  std::vector<Eigen::Vector3d> seeds;
  for (std::size_t k = 0; k < n_patches; ++k) {
    if (start[k + 1] - start[k] < 5) continue;
    float zmin = std::numeric_limits<float>::max();
    for (std::size_t q = start[k]; q < start[k + 1]; ++q) zmin = std::min(zmin, points[order[q]].z());
    seeds.clear();
    for (std::size_t q = start[k]; q < start[k + 1]; ++q)
      if (points[order[q]].z() < zmin + o.seed_band_m) seeds.push_back(points[order[q]].cast<double>());
    Eigen::Vector3d n, c;
    if (!fit_plane(seeds, n, c) || n.z() < min_nz) continue;
    // One refit on the points within the threshold of the first plane.
    seeds.clear();
    for (std::size_t q = start[k]; q < start[k + 1]; ++q) {
      const Eigen::Vector3d p = points[order[q]].cast<double>();
      if (std::abs(n.dot(p - c)) < o.distance_m) seeds.push_back(p);
    }
    if (!fit_plane(seeds, n, c) || n.z() < min_nz) continue;
    planes[k] = Eigen::Vector3d(-n.x() / n.z(), -n.y() / n.z(), n.dot(c) / n.z());
    fitted[k] = 1;
  }
  // A patch standing above its fitted neighbours (within 3 patches) by more
  // than max_step_m is a table, a box or a ledge seen without floor under it.
  const auto centre_z = [&](std::size_t k, int i, int j) {
    const double x = lo.x() + (i + 0.5) * o.patch_m, y = lo.y() + (j + 0.5) * o.patch_m;
    return planes[k].x() * x + planes[k].y() * y + planes[k].z();
  };
  std::vector<std::uint8_t> keep = fitted;
  std::vector<double> around;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * nx + i;
      if (!fitted[k]) continue;
      around.clear();
      for (int dj = -3; dj <= 3; ++dj)
        for (int di = -3; di <= 3; ++di) {
          const int a = i + di, b = j + dj;
          if ((di == 0 && dj == 0) || a < 0 || b < 0 || a >= nx || b >= ny) continue;
          const std::size_t m = static_cast<std::size_t>(b) * nx + a;
          if (fitted[m]) around.push_back(centre_z(m, i, j));
        }
      if (around.size() < 3) continue;
      std::nth_element(around.begin(), around.begin() + around.size() / 2, around.end());
      if (centre_z(k, i, j) > around[around.size() / 2] + o.max_step_m) keep[k] = 0;
    }
  // Patches without ground take their nearest kept neighbour's plane (BFS).
  std::deque<std::size_t> queue;
  std::vector<std::uint8_t> has(n_patches, 0);
  for (std::size_t k = 0; k < n_patches; ++k)
    if (keep[k]) {
      has[k] = 1;
      queue.push_back(k);
    }
  while (!queue.empty()) {
    const std::size_t k = queue.front();
    queue.pop_front();
    const int i = static_cast<int>(k % nx), j = static_cast<int>(k / nx);
    const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
    for (int d = 0; d < 4; ++d) {
      const int a = i + di[d], b = j + dj[d];
      if (a < 0 || b < 0 || a >= nx || b >= ny) continue;
      const std::size_t m = static_cast<std::size_t>(b) * nx + a;
      if (has[m]) continue;
      has[m] = 1;
      planes[m] = planes[k];
      queue.push_back(m);
    }
  }
  out.model = GroundModel(lo, o.patch_m, nx, ny, std::move(planes), std::move(keep));
  if (out.model.fitted_patches() == 0) {
    out.model = GroundModel();
    return out;  // no ground seen: nothing labelled
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (std::abs(p.z() - out.model.height_at(p.x(), p.y())) < o.distance_m) {
      out.is_ground[i] = 1;
      ++out.ground_points;
    }
  }
  return out;
}

}  // namespace adit::products
