#include "adit/eval/grid_truth.hpp"

#include <algorithm>
#include <cmath>
#include <deque>

namespace adit::eval {
namespace {

constexpr std::int8_t kUnknown = -1, kFree = 0, kOccupied = 100;

struct Lattice {
  double cell = 0.05, x0 = 0.0, y0 = 0.0;
  int w = 0, h = 0;
  std::size_t index(int c, int r) const { return static_cast<std::size_t>(r) * w + c; }
  bool contains(int c, int r) const { return c >= 0 && r >= 0 && c < w && r < h; }
  int col(double x) const { return static_cast<int>(std::floor((x - x0) / cell)); }
  int row(double y) const { return static_cast<int>(std::floor((y - y0) / cell)); }
};

// Marks the cells the segment a-b passes (samples a quarter cell apart: an
// 8-connected line, which a 4-connected fill cannot cross).
void draw(const Lattice& l, std::vector<std::uint8_t>& occ, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const int n = static_cast<int>(std::ceil((b - a).norm() / (l.cell / 4))) + 1;
  for (int k = 0; k <= n; ++k) {
    const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(k) / n);
    const int c = l.col(p.x()), r = l.row(p.y());
    if (l.contains(c, r)) occ[l.index(c, r)] = 1;
  }
}

// The segment where triangle t crosses the plane z = h (world), if it does.
bool slice(const Triangle& t, double h, Eigen::Vector3d& p, Eigen::Vector3d& q) {
  const Eigen::Vector3d* v[3] = {&t.a, &t.b, &t.c};
  Eigen::Vector3d out[2];
  int n = 0;
  for (int i = 0; i < 3 && n < 2; ++i) {
    const Eigen::Vector3d& a = *v[i];
    const Eigen::Vector3d& b = *v[(i + 1) % 3];
    const double da = a.z() - h, db = b.z() - h;
    if ((da < 0) == (db < 0) || da == db) continue;
    out[n++] = a + (b - a) * (da / (da - db));
  }
  if (n < 2) return false;
  p = out[0];
  q = out[1];
  return true;
}

double iou(std::size_t both, std::size_t either) { return either == 0 ? 0.0 : static_cast<double>(both) / either; }

}  // namespace

GridTruthScore score_grid(const GridView& grid, std::span<const Triangle> scene, const Eigen::Isometry3d& map_from_world,
                          std::span<const Eigen::Vector3d> path_world, const GridTruthOptions& o) {
  GridTruthScore s;
  Lattice l;
  l.cell = o.cell_m;
  l.x0 = grid.origin_x;
  l.y0 = grid.origin_y;
  l.w = static_cast<int>(std::ceil(grid.width * grid.resolution_m / o.cell_m));
  l.h = static_cast<int>(std::ceil(grid.height * grid.resolution_m / o.cell_m));
  if (l.w <= 0 || l.h <= 0 || path_world.empty()) return s;
  const std::size_t n = static_cast<std::size_t>(l.w) * l.h;

  // The grid on the truth's lattice: occupied if any of its cells there is, else free if half are.
  std::vector<std::int8_t> est(n, kUnknown);
  {
    std::vector<std::uint16_t> occ(n, 0), fre(n, 0), all(n, 0);
    for (int r = 0; r < grid.height; ++r)
      for (int c = 0; c < grid.width; ++c) {
        const int tc = l.col(grid.origin_x + (c + 0.5) * grid.resolution_m);
        const int tr = l.row(grid.origin_y + (r + 0.5) * grid.resolution_m);
        if (!l.contains(tc, tr)) continue;
        const std::size_t k = l.index(tc, tr);
        const std::int8_t v = grid.cells[static_cast<std::size_t>(r) * grid.width + c];
        ++all[k];
        if (v == kOccupied) ++occ[k];
        if (v == kFree) ++fre[k];
      }
    for (std::size_t k = 0; k < n; ++k)
      est[k] = occ[k] > 0 ? kOccupied : (all[k] > 0 && 2 * fre[k] >= all[k]) ? kFree : kUnknown;
  }

  // Truth occupied: the scene sliced across the band.
  std::vector<std::uint8_t> occ(n, 0);
  Eigen::Vector3d p, q;
  for (double h = o.floor_z + o.band_low_m; h <= o.floor_z + o.band_high_m + 1e-9; h += 0.1)
    for (const Triangle& t : scene)
      if (slice(t, h, p, q)) draw(l, occ, (map_from_world * p).head<2>(), (map_from_world * q).head<2>());

  // The path in the grid's frame, a viewpoint every path_step_m.
  std::vector<Eigen::Vector2d> views;
  for (const Eigen::Vector3d& w : path_world) {
    const Eigen::Vector2d m = (map_from_world * w).head<2>();
    if (views.empty() || (m - views.back()).norm() >= o.path_step_m) views.push_back(m);
  }
  // Truth free: reached from the path.
  std::vector<std::uint8_t> fre(n, 0);
  std::deque<std::size_t> queue;
  for (const Eigen::Vector2d& v : views) {
    const int c = l.col(v.x()), r = l.row(v.y());
    if (l.contains(c, r) && !occ[l.index(c, r)] && !fre[l.index(c, r)]) {
      fre[l.index(c, r)] = 1;
      queue.push_back(l.index(c, r));
    }
  }
  while (!queue.empty()) {
    const std::size_t k = queue.front();
    queue.pop_front();
    const int c = static_cast<int>(k % l.w), r = static_cast<int>(k / l.w);
    const int dc[4] = {1, -1, 0, 0}, dr[4] = {0, 0, 1, -1};
    for (int d = 0; d < 4; ++d) {
      const int a = c + dc[d], b = r + dr[d];
      if (!l.contains(a, b)) continue;
      const std::size_t m = l.index(a, b);
      if (occ[m] || fre[m]) continue;
      fre[m] = 1;
      queue.push_back(m);
    }
  }
  // What a sensor on the path sees in 2D, and what is in range.
  std::vector<std::uint8_t> seen(n, 0), in_range(n, 0);
  const double step = l.cell / 2;
  for (const Eigen::Vector2d& v : views) {
    const int reach = static_cast<int>(std::ceil(o.max_range_m / l.cell));
    const int vc = l.col(v.x()), vr = l.row(v.y());
    for (int r = std::max(0, vr - reach); r <= std::min(l.h - 1, vr + reach); ++r)
      for (int c = std::max(0, vc - reach); c <= std::min(l.w - 1, vc + reach); ++c)
        if (std::hypot((c - vc) * l.cell, (r - vr) * l.cell) <= o.max_range_m) in_range[l.index(c, r)] = 1;
    for (int k = 0; k < o.rays; ++k) {
      const double a = 2 * M_PI * k / o.rays;
      const Eigen::Vector2d d(std::cos(a), std::sin(a));
      for (double t = 0; t <= o.max_range_m; t += step) {
        const Eigen::Vector2d x = v + t * d;
        const int c = l.col(x.x()), r = l.row(x.y());
        if (!l.contains(c, r)) break;
        seen[l.index(c, r)] = 1;
        if (occ[l.index(c, r)]) break;
      }
    }
  }
  const auto near_occupied = [&](const std::vector<std::uint8_t>& mask, int c, int r) {
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc)
        if (l.contains(c + dc, r + dr) && mask[l.index(c + dc, r + dr)]) return true;
    return false;
  };
  std::vector<std::uint8_t> est_occ(n, 0), truth_occ(n, 0);
  for (std::size_t k = 0; k < n; ++k) {
    est_occ[k] = in_range[k] && est[k] == kOccupied;
    truth_occ[k] = in_range[k] && seen[k] && occ[k];
  }
  std::size_t free_both = 0, free_either = 0, occ_both = 0, occ_either = 0, known_both = 0, known_either = 0;
  std::size_t est_matched = 0, truth_unmatched = 0;
  s.lattice_width = l.w;
  s.lattice_height = l.h;
  s.cells.assign(n, CellAgreement::unscored);
  for (int r = 0; r < l.h; ++r)
    for (int c = 0; c < l.w; ++c) {
      const std::size_t k = l.index(c, r);
      if (!in_range[k]) continue;
      const bool tf = seen[k] && fre[k] && !occ[k], to = truth_occ[k] != 0;
      const bool ef = est[k] == kFree, eo = est_occ[k] != 0;
      s.truth_free += tf;
      s.truth_occupied += to;
      s.grid_free += ef;
      s.grid_occupied += eo;
      free_both += tf && ef;
      free_either += tf || ef;
      occ_both += to && eo;
      occ_either += to || eo;
      known_both += (tf || to) && (ef || eo);
      known_either += (tf || to) || (ef || eo);
      const bool eo_matched = eo && near_occupied(occ, c, r);
      const bool to_unmatched = to && !near_occupied(est_occ, c, r);
      est_matched += eo_matched;
      truth_unmatched += to_unmatched;
      CellAgreement& a = s.cells[k];
      a = tf && ef                                 ? CellAgreement::free_both
          : tf && !eo                              ? CellAgreement::free_truth_unknown
          : tf                                     ? (eo_matched ? CellAgreement::occupied_both : CellAgreement::occupied_grid_only)
          : to_unmatched                           ? CellAgreement::occupied_truth_only
          : (to || eo_matched)                     ? CellAgreement::occupied_both
          : ef                                     ? CellAgreement::free_grid_only
          : eo                                     ? CellAgreement::occupied_grid_only
                                                   : CellAgreement::unseen_both;
    }
  s.iou_free = iou(free_both, free_either);
  s.iou_occupied = iou(occ_both, occ_either);
  s.iou_occupied_within_1_cell = iou(est_matched, s.grid_occupied + truth_unmatched);
  s.iou_known = iou(known_both, known_either);
  return s;
}

}  // namespace adit::eval
