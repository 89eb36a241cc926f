#include "adit/products/grid_projection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace adit::products {

Grid2d project_to_grid(const Occupancy3d& occupancy, std::span<const Eigen::Vector3f> points,
                       std::span<const std::uint8_t> obstacle, std::span<const std::uint8_t> floor,
                       const GroundModel& ground,
                       const ProjectionOptions& o) {
  Grid2d g;
  g.resolution_m = o.resolution_m;
  double lo_x = std::numeric_limits<double>::max(), lo_y = lo_x, hi_x = -lo_x, hi_y = -lo_x;
  occupancy.for_each_leaf([&](const Eigen::Vector3f& c, double size, bool) {
    lo_x = std::min(lo_x, c.x() - size / 2);
    lo_y = std::min(lo_y, c.y() - size / 2);
    hi_x = std::max(hi_x, c.x() + size / 2);
    hi_y = std::max(hi_y, c.y() + size / 2);
  });
  for (const Eigen::Vector3f& p : points) {
    lo_x = std::min(lo_x, double{p.x()});
    lo_y = std::min(lo_y, double{p.y()});
    hi_x = std::max(hi_x, double{p.x()});
    hi_y = std::max(hi_y, double{p.y()});
  }
  if (lo_x > hi_x) return g;
  // The grid's corner on a multiple of the resolution: grids of one session line up.
  g.origin_x = std::floor(lo_x / o.resolution_m) * o.resolution_m;
  g.origin_y = std::floor(lo_y / o.resolution_m) * o.resolution_m;
  g.width = static_cast<int>(std::ceil((hi_x - g.origin_x) / o.resolution_m)) + 1;
  g.height = static_cast<int>(std::ceil((hi_y - g.origin_y) / o.resolution_m)) + 1;
  g.cells.assign(static_cast<std::size_t>(g.width) * g.height, kUnknown);
  const auto in_band = [&](double x, double y, double z) {
    const double h = z - ground.height_at(x, y);
    return h >= o.band_low_m && h <= o.band_high_m;
  };
  // Free: the footprint of every free leaf whose centre is in the band (a
  // pruned leaf is larger than a voxel; its centre stands for it).
  occupancy.for_each_leaf([&](const Eigen::Vector3f& c, double size, bool occupied) {
    if (occupied || !in_band(c.x(), c.y(), c.z())) return;
    const int c0 = std::max(0, g.col_of(c.x() - size / 2 + 1e-6)), c1 = std::min(g.width - 1, g.col_of(c.x() + size / 2 - 1e-6));
    const int r0 = std::max(0, g.row_of(c.y() - size / 2 + 1e-6)), r1 = std::min(g.height - 1, g.row_of(c.y() + size / 2 - 1e-6));
    for (int r = r0; r <= r1; ++r)
      for (int col = c0; col <= c1; ++col) g.at(col, r) = kFree;
  });
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!floor[i]) continue;
    const int col = g.col_of(points[i].x()), row = g.row_of(points[i].y());
    if (g.contains(col, row)) g.at(col, row) = kFree;
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!obstacle[i] || !in_band(p.x(), p.y(), p.z())) continue;
    const int col = g.col_of(p.x()), row = g.row_of(p.y());
    if (g.contains(col, row)) g.at(col, row) = kOccupied;
  }
  return g;
}

std::size_t fill_line_of_sight(Grid2d& g, std::span<const Eigen::Vector3f> viewpoints, double range_m,
                               double viewpoint_step_m) {
  if (g.cells.empty()) return 0;
  std::vector<std::uint8_t> block(g.cells.size(), 0);
  for (int r = 0; r < g.height; ++r)
    for (int c = 0; c < g.width; ++c) {
      if (g.at(c, r) != kOccupied) continue;
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc)
          if (g.contains(c + dc, r + dr)) block[static_cast<std::size_t>(r + dr) * g.width + c + dc] = 1;
    }
  std::vector<std::size_t> cells;
  std::size_t filled = 0;
  const int rays = 1440;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const double t_end = range_m / g.resolution_m;  // in cells
  Eigen::Vector3f last(std::numeric_limits<float>::max(), 0, 0);
  for (const Eigen::Vector3f& v : viewpoints) {
    if ((v - last).norm() < viewpoint_step_m) continue;
    last = v;
    const double gx = (v.x() - g.origin_x) / g.resolution_m, gy = (v.y() - g.origin_y) / g.resolution_m;
    for (int k = 0; k < rays; ++k) {
      const double a = 2 * M_PI * k / rays, dx = std::cos(a), dy = std::sin(a);
      cells.clear();
      bool bounded = false;
      std::size_t seen = 0;  // cells up to the last one already free
      // Every cell the ray crosses, in order (Amanatides and Woo, "A fast voxel
      // traversal algorithm for ray tracing", Eurographics 1987): t is the
      // distance along the ray in cells, t_c and t_r where it next crosses a
      // column and a row boundary.
      int c = static_cast<int>(std::floor(gx)), r = static_cast<int>(std::floor(gy));
      const int step_c = dx > 0 ? 1 : -1, step_r = dy > 0 ? 1 : -1;
      const double delta_c = dx != 0 ? 1.0 / std::abs(dx) : kInf, delta_r = dy != 0 ? 1.0 / std::abs(dy) : kInf;
      double t_c = dx > 0 ? (c + 1 - gx) * delta_c : dx < 0 ? (gx - c) * delta_c : kInf;
      double t_r = dy > 0 ? (r + 1 - gy) * delta_r : dy < 0 ? (gy - r) * delta_r : kInf;
      for (double t = 0; t <= t_end;) {
        if (!g.contains(c, r)) break;
        const std::size_t k2 = static_cast<std::size_t>(r) * g.width + c;
        if (block[k2]) {
          bounded = true;
          break;
        }
        cells.push_back(k2);
        if (g.cells[k2] == kFree) seen = cells.size();
        if (t_c < t_r) {
          t = t_c;
          t_c += delta_c;
          c += step_c;
        } else {
          t = t_r;
          t_r += delta_r;
          r += step_r;
        }
      }
      // A ray that met no obstacle (through a sparse far wall, a door) fills
      // only up to the last cell already seen free along it.
      if (!bounded) cells.resize(seen);
      for (const std::size_t k2 : cells)
        if (g.cells[k2] == kUnknown) {
          g.cells[k2] = kFree;
          ++filled;
        }
    }
  }
  return filled;
}

}  // namespace adit::products
