#include "adit/slam/prior_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "adit/slam/voxel_downsample.hpp"

namespace adit::slam {
namespace {

// Voxel hash capacity for n points spread over surfaces at `spacing` in voxels of `voxel`.
std::size_t capacity_for(std::size_t n, float spacing, float voxel) {
  const double per_voxel = std::max(1.0, static_cast<double>(voxel * voxel) / static_cast<double>(spacing * spacing) / 2.0);
  return std::max<std::size_t>(1024, static_cast<std::size_t>(2.0 * static_cast<double>(n) / per_voxel));
}

constexpr float kMaxPlanExtentM = 5000.0F;

PlanGrid draw_plan(const PriorMap& prior, const PriorMapConfig& config) {
  PlanGrid plan;
  plan.cell_m = config.plan_cell_m;
  Eigen::Vector2f lo = Eigen::Vector2f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector2f hi = -lo;
  for (const auto& p : prior.points) {
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  // A plan larger than 5 km a side is not a site (millimetres read as metres):
  // left empty, and check_prior_map says why.
  if ((hi - lo).maxCoeff() > kMaxPlanExtentM) return plan;
  const float margin = 1.0F;
  plan.origin = lo - Eigen::Vector2f::Constant(margin);
  plan.width = static_cast<int>(std::ceil((hi.x() - lo.x() + 2 * margin) / plan.cell_m)) + 1;
  plan.height = static_cast<int>(std::ceil((hi.y() - lo.y() + 2 * margin) / plan.cell_m)) + 1;
  const std::size_t cells = static_cast<std::size_t>(plan.width) * static_cast<std::size_t>(plan.height);
  plan.likelihood.assign(cells, 0.0F);
  plan.floor_z.assign(cells, std::numeric_limits<float>::quiet_NaN());
  constexpr float kCap = 2.0F;
  plan.wall_distance.assign(cells, kCap);
  std::vector<std::uint8_t> wall(cells, 0);
  const auto cell_of = [&](const Eigen::Vector3f& p, int& ix, int& iy) {
    ix = static_cast<int>(std::floor((p.x() - plan.origin.x()) / plan.cell_m));
    iy = static_cast<int>(std::floor((p.y() - plan.origin.y()) / plan.cell_m));
    return plan.contains(ix, iy);
  };
  for (std::size_t i = 0; i < prior.points.size(); ++i) {
    const Eigen::Vector3f& n = prior.normals[i];
    if (n.isZero()) continue;
    int ix = 0, iy = 0;
    if (!cell_of(prior.points[i], ix, iy)) continue;
    const std::size_t c = plan.index(ix, iy);
    if (std::abs(n.z()) < config.vertical_max_nz) wall[c] = 1;
    if (std::abs(n.z()) > config.horizontal_min_nz) {
      float& f = plan.floor_z[c];
      if (std::isnan(f) || prior.points[i].z() < f) f = prior.points[i].z();
    }
  }
  // Distances to the nearest wall cell, stamped round each wall cell (a
  // brute-force distance transform within the cap: walls are a small share of the cells).
  const int reach = static_cast<int>(std::ceil(kCap / plan.cell_m));
  for (int iy = 0; iy < plan.height; ++iy) {
    for (int ix = 0; ix < plan.width; ++ix) {
      if (wall[plan.index(ix, iy)] == 0) continue;
      for (int dy = -reach; dy <= reach; ++dy) {
        for (int dx = -reach; dx <= reach; ++dx) {
          if (!plan.contains(ix + dx, iy + dy)) continue;
          const float d = plan.cell_m * std::sqrt(static_cast<float>(dx * dx + dy * dy));
          float& w = plan.wall_distance[plan.index(ix + dx, iy + dy)];
          w = std::min(w, d);
        }
      }
    }
  }
  const float s2 = 2.0F * config.plan_sigma_m * config.plan_sigma_m;
  for (std::size_t c = 0; c < cells; ++c) {
    const float d = plan.wall_distance[c];
    plan.likelihood[c] = d > 3.0F * config.plan_sigma_m ? 0.0F : std::exp(-d * d / s2);
  }
  return plan;
}

}  // namespace

PriorMap prepare_prior_map(std::span<const Eigen::Vector3f> points, const PriorMapConfig& config) {
  std::vector<Eigen::Vector3f> finite;
  finite.reserve(points.size());
  for (const auto& p : points)
    if (p.allFinite()) finite.push_back(p);
  if (finite.empty()) throw std::invalid_argument("the prior map has no finite points");
  PriorMap prior;
  prior.point_spacing_m = config.point_spacing_m;
  VoxelDownsampler downsampler(finite.size());
  prior.points.resize(finite.size());
  prior.points.resize(downsampler.downsample(finite, config.point_spacing_m, prior.points));

  VoxelHashMap index(config.normal_radius_m, capacity_for(prior.points.size(), config.point_spacing_m, config.normal_radius_m));
  index.add(prior.points);
  prior.normals.assign(prior.points.size(), Eigen::Vector3f::Zero());
  for (std::size_t i = 0; i < prior.points.size(); ++i) {
    const MapPlane plane = index.nearest_plane(prior.points[i], config.normal_neighbors, 0.5F * config.point_spacing_m);
    if (!plane.found) continue;
    prior.normals[i] = plane.normal;
    const float nz = std::abs(plane.normal.z());
    if (nz < config.vertical_max_nz) ++prior.vertical_points;
    if (nz > config.horizontal_min_nz) ++prior.horizontal_points;
  }
  prior.plan = draw_plan(prior, config);
  return prior;
}

std::string check_prior_map(const PriorMap& prior) {
  if (prior.points.size() < 100) return fmt::format("only {} points: too few to localise against", prior.points.size());
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f hi = -lo;
  std::size_t y_facing = 0;
  for (std::size_t i = 0; i < prior.points.size(); ++i) {
    lo = lo.cwiseMin(prior.points[i]);
    hi = hi.cwiseMax(prior.points[i]);
    if (std::abs(prior.normals[i].y()) > 0.9F) ++y_facing;
  }
  const Eigen::Vector3f extent = hi - lo;
  if (extent.maxCoeff() > 5000.0F)
    return fmt::format("it spans {:.0f} x {:.0f} x {:.0f} m: millimetres read as metres? (scale it by 0.001)",
                       extent.x(), extent.y(), extent.z());
  const double n = static_cast<double>(prior.points.size());
  if (prior.plan.likelihood.empty()) return "no plan could be drawn";
  if (static_cast<double>(prior.vertical_points) < 0.05 * n)
    return fmt::format("only {:.1f} % of its surfaces are vertical: no walls to localise on",
                       100.0 * static_cast<double>(prior.vertical_points) / n);
  if (static_cast<double>(prior.horizontal_points) < 0.01 * n)
    return "it has no floor (no horizontal surface): z up?";
  // A Y-up export read as Z-up turns a storey on its side: taller than it is wide.
  if (extent.z() > std::min(extent.x(), extent.y()))
    return fmt::format("it is {:.1f} m tall but {:.1f} m wide: exported Y-up? (rotate it to z up: --up y)", extent.z(),
                       std::min(extent.x(), extent.y()));
  // Floors standing upright (a Y-up export read as Z-up) cover the plan with
  // walls: hardly a floor cell is clear of them.
  std::size_t floor = 0, free = 0;
  for (std::size_t c = 0; c < prior.plan.floor_z.size(); ++c) {
    if (std::isnan(prior.plan.floor_z[c])) continue;
    ++floor;
    free += prior.plan.wall_distance[c] >= 0.3F ? 1 : 0;
  }
  if (static_cast<double>(free) < 0.1 * static_cast<double>(floor))
    return fmt::format("only {} of its {} floor cells are clear of walls, {:.1f} % of its surfaces face along y: "
                       "exported Y-up? (rotate it to z up: --up y)",
                       free, floor, 100.0 * static_cast<double>(y_facing) / n);
  return {};
}

VoxelHashMap index_prior_map(const PriorMap& prior, float voxel_m) {
  // A voxel keeps at most kMaxPointsPerVoxel points: thinned to a quarter of
  // its edge, a planar voxel holds about 16, so none is cut to its first few.
  const float spacing = std::max(prior.point_spacing_m, 0.25F * voxel_m);
  std::vector<Eigen::Vector3f> thinned(prior.points.size());
  VoxelDownsampler downsampler(prior.points.size());
  thinned.resize(downsampler.downsample(prior.points, spacing, thinned));
  VoxelHashMap index(voxel_m, capacity_for(thinned.size(), spacing, voxel_m));
  index.add(thinned);
  return index;
}

}  // namespace adit::slam
