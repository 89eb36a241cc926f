#include "adit/products/target_finder.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <fstream>
#include <limits>
#include <unordered_map>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::products {
namespace {

std::int64_t key_of(int x, int y, int z) {
  return (static_cast<std::int64_t>(x + (1 << 20)) << 42) | (static_cast<std::int64_t>(y + (1 << 20)) << 21) |
         static_cast<std::int64_t>(z + (1 << 20));
}

}  // namespace

std::vector<FoundTarget> find_targets(std::span<const Eigen::Vector3f> points, std::span<const float> intensities,
                                      const slam::Trajectory& path, const TargetOptions& o) {
  std::vector<std::size_t> bright;
  for (std::size_t i = 0; i < points.size() && i < intensities.size(); ++i)
    if (intensities[i] >= o.min_intensity) bright.push_back(i);
  // Bright points by voxel.
  std::unordered_map<std::int64_t, std::vector<std::size_t>> voxels;
  const auto cell = [&](float v) { return static_cast<int>(std::floor(v / o.cluster_m)); };
  for (const std::size_t i : bright)
    voxels[key_of(cell(points[i].x()), cell(points[i].y()), cell(points[i].z()))].push_back(i);
  std::unordered_map<std::int64_t, bool> seen;
  std::vector<std::pair<std::size_t, FoundTarget>> found;  // (nearest path index, target)
  for (const auto& [start_key, start_points] : voxels) {
    if (seen[start_key]) continue;
    seen[start_key] = true;
    std::vector<std::size_t> members;
    std::deque<std::int64_t> queue{start_key};
    while (!queue.empty()) {
      const std::int64_t k = queue.front();
      queue.pop_front();
      const std::vector<std::size_t>& here = voxels.at(k);
      members.insert(members.end(), here.begin(), here.end());
      const Eigen::Vector3f& p = points[here.front()];
      const int x = cell(p.x()), y = cell(p.y()), z = cell(p.z());
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const std::int64_t n = key_of(x + dx, y + dy, z + dz);
            if (!voxels.contains(n) || seen[n]) continue;
            seen[n] = true;
            queue.push_back(n);
          }
    }
    if (static_cast<int>(members.size()) < o.min_points) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max()), hi = -lo;
    for (const std::size_t i : members) {
      const Eigen::Vector3d p = points[i].cast<double>();
      mean += p;
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    mean /= static_cast<double>(members.size());
    if ((hi - lo).norm() > o.max_extent_m) continue;
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const std::size_t i : members) {
      const Eigen::Vector3d d = points[i].cast<double>() - mean;
      cov += d * d.transpose();
    }
    cov /= static_cast<double>(members.size());
    const double plane_var = std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvalues()(0));
    FoundTarget t;
    t.centre = mean;
    t.points = static_cast<int>(members.size());
    t.sigma_m = std::sqrt((plane_var + o.voxel_m * o.voxel_m / 12.0) / static_cast<double>(members.size()));
    // Along the path, and within reach of it.
    std::size_t nearest = 0;
    double best = std::numeric_limits<double>::max();
    for (std::size_t k = 0; k < path.size(); ++k) {
      const double d = (path.poses[k].translation() - mean).norm();
      if (d < best) {
        best = d;
        nearest = k;
      }
    }
    if (!path.empty() && best > o.max_path_distance_m) continue;
    found.emplace_back(nearest, t);
  }
  std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first < b.first : a.second.centre.x() < b.second.centre.x();
  });
  std::vector<FoundTarget> out;
  for (auto& [k, t] : found) {
    t.id = static_cast<int>(out.size()) + 1;
    out.push_back(t);
  }
  return out;
}

void write_targets_csv(const std::filesystem::path& file, std::span<const FoundTarget> targets) {
  std::ofstream out(file);
  if (!out) throw InputError(file.string(), "", "cannot open for writing");
  out << "id,x,y,z,sigma_m\n";
  for (const FoundTarget& t : targets)
    out << fmt::format("{},{:.4f},{:.4f},{:.4f},{:.4f}\n", t.id, t.centre.x(), t.centre.y(), t.centre.z(), t.sigma_m);
  if (!out) throw InputError(file.string(), "", "write failed");
}

}  // namespace adit::products
