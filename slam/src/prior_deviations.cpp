#include "adit/slam/prior_deviations.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "adit/slam/voxel_key.hpp"

namespace adit::slam {

std::vector<float> signed_deviations(std::span<const Eigen::Vector3f> points,
                                     std::span<const Eigen::Vector3f> viewpoints, const PriorMap& prior,
                                     const DeviationConfig& config) {
  VoxelHashMap views(config.viewpoint_voxel_m, std::max<std::size_t>(1024, 2 * viewpoints.size()));
  views.add(viewpoints);
  // The prior's points by cell of max_distance_m: the 27 cells round a point hold every one within reach.
  const float inv = 1.0F / config.max_distance_m;
  std::unordered_map<VoxelKey, std::vector<std::uint32_t>, VoxelKeyHash> cells;
  for (std::size_t i = 0; i < prior.points.size(); ++i) cells[voxel_key(prior.points[i], inv)].push_back(static_cast<std::uint32_t>(i));
  const float reach2 = config.max_distance_m * config.max_distance_m;
  const float patch = config.patch_spacings * prior.point_spacing_m;
  const float patch2 = patch * patch;
  std::vector<float> out(points.size(), config.max_distance_m);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    const VoxelKey c = voxel_key(p, inv);
    // The smallest distance to a piece of the prior's surface: a point's plane
    // where p lies over its patch, else the point itself (module header).
    float best = reach2;
    std::int64_t nearest = -1;
    bool on_plane = false;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells.find(VoxelKey{c.x + dx, c.y + dy, c.z + dz});
          if (it == cells.end()) continue;
          for (const std::uint32_t k : it->second) {
            const Eigen::Vector3f delta = p - prior.points[k];
            const float d2 = delta.squaredNorm();
            if (d2 >= reach2) continue;
            const Eigen::Vector3f& n = prior.normals[k];
            const float along = n.dot(delta);
            const bool over_patch = !n.isZero() && d2 - along * along <= patch2;
            const float candidate = over_patch ? along * along : d2;
            if (candidate < best) {
              best = candidate;
              nearest = k;
              on_plane = over_patch;
            }
          }
        }
    if (nearest < 0) continue;  // the designed free space: +max_distance_m
    const Eigen::Vector3f delta = p - prior.points[static_cast<std::size_t>(nearest)];
    Eigen::Vector3f normal = prior.normals[static_cast<std::size_t>(nearest)];
    float d = 0.0F;
    if (on_plane) {
      d = normal.dot(delta);
    } else {
      d = delta.norm();
      normal = d > 0.0F ? Eigen::Vector3f(delta / d) : Eigen::Vector3f::UnitZ();
    }
    // Towards the observer is positive.
    const MapNeighbor view = views.nearest(p);
    if (view.found && normal.dot(view.point - p) * d < 0.0F) d = -std::abs(d);
    else d = std::abs(d);
    out[i] = std::clamp(d, -config.max_distance_m, config.max_distance_m);
  }
  return out;
}

std::vector<float> smooth_deviations(std::span<const Eigen::Vector3f> points, std::span<const float> deviations,
                                     float voxel_m) {
  std::unordered_map<VoxelKey, std::pair<double, int>, VoxelKeyHash> sums;
  const float inv = 1.0F / voxel_m;
  for (std::size_t i = 0; i < points.size(); ++i) {
    auto& [sum, n] = sums[voxel_key(points[i], inv)];
    sum += deviations[i];
    ++n;
  }
  std::vector<float> out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto& [sum, n] = sums.at(voxel_key(points[i], inv));
    out[i] = static_cast<float>(sum / n);
  }
  return out;
}

std::vector<DeviationRegion> deviation_regions(std::span<const Eigen::Vector3f> points,
                                               std::span<const float> deviations, const DeviationConfig& config,
                                               std::span<int> member) {
  std::fill(member.begin(), member.end(), -1);
  // Deviating points by voxel, among all the points of each voxel; a voxel
  // deviates when at least region_min_share of its points do (a vote: range
  // noise alone puts a few percent of a surface's points past the threshold,
  // scattered, and would otherwise link whole walls into regions).
  struct Voxel {
    std::size_t points = 0;
    std::vector<std::size_t> deviating;
  };
  std::unordered_map<VoxelKey, Voxel, VoxelKeyHash> all;
  const float inv = 1.0F / config.region_voxel_m;
  for (std::size_t i = 0; i < points.size(); ++i) {
    Voxel& v = all[voxel_key(points[i], inv)];
    ++v.points;
    if (std::abs(deviations[i]) > config.threshold_m) v.deviating.push_back(i);
  }
  std::unordered_map<VoxelKey, std::vector<std::size_t>, VoxelKeyHash> voxels;
  for (auto& [key, v] : all)
    if (!v.deviating.empty() &&
        static_cast<double>(v.deviating.size()) >= config.region_min_share * static_cast<double>(v.points))
      voxels.emplace(key, std::move(v.deviating));
  std::unordered_map<VoxelKey, int, VoxelKeyHash> label;
  std::vector<DeviationRegion> regions;
  std::vector<std::vector<std::size_t>> region_points;
  std::vector<VoxelKey> stack;
  for (const auto& [seed, _] : voxels) {
    if (label.contains(seed)) continue;
    const int id = static_cast<int>(region_points.size());
    region_points.emplace_back();
    label[seed] = id;
    stack.push_back(seed);
    while (!stack.empty()) {
      const VoxelKey k = stack.back();
      stack.pop_back();
      const auto& held = voxels.at(k);
      region_points.back().insert(region_points.back().end(), held.begin(), held.end());
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const VoxelKey n{k.x + dx, k.y + dy, k.z + dz};
            if (!voxels.contains(n) || label.contains(n)) continue;
            label[n] = id;
            stack.push_back(n);
          }
    }
  }
  std::vector<int> kept_id(region_points.size(), -1);
  for (std::size_t r = 0; r < region_points.size(); ++r) {
    const auto& idx = region_points[r];
    if (idx.size() < config.min_region_points) continue;
    DeviationRegion region;
    region.points = idx.size();
    region.lo = region.hi = points[idx.front()];
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double dev = 0.0;
    for (const std::size_t i : idx) {
      region.lo = region.lo.cwiseMin(points[i]);
      region.hi = region.hi.cwiseMax(points[i]);
      sum += points[i].cast<double>();
      dev += deviations[i];
      region.max_abs_m = std::max(region.max_abs_m, std::abs(deviations[i]));
    }
    region.centroid = (sum / static_cast<double>(idx.size())).cast<float>();
    region.mean_m = static_cast<float>(dev / static_cast<double>(idx.size()));
    kept_id[r] = static_cast<int>(regions.size());
    regions.push_back(region);
  }
  // Largest first.
  std::vector<int> order(regions.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return regions[static_cast<std::size_t>(a)].points > regions[static_cast<std::size_t>(b)].points; });
  std::vector<int> rank(regions.size());
  std::vector<DeviationRegion> sorted;
  for (std::size_t k = 0; k < order.size(); ++k) {
    rank[static_cast<std::size_t>(order[k])] = static_cast<int>(k);
    sorted.push_back(regions[static_cast<std::size_t>(order[k])]);
  }
  if (!member.empty())
    for (std::size_t r = 0; r < region_points.size(); ++r)
      if (kept_id[r] >= 0)
        for (const std::size_t i : region_points[r]) member[i] = rank[static_cast<std::size_t>(kept_id[r])];
  return sorted;
}

}  // namespace adit::slam
