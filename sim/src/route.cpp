#include <cmath>

#include "adit/sim/scene.hpp"

namespace adit::sim {

double Route::length() const { return points.size() < 2 ? 0.0 : step * static_cast<double>(points.size() - (closed ? 0 : 1)); }

Route smooth_route(const std::vector<Eigen::Vector2d>& polyline, bool closed, double max_piece_m) {
  std::vector<Eigen::Vector2d> p;
  const std::size_t n = polyline.size();
  const std::size_t edges = closed ? n : n - 1;
  for (std::size_t i = 0; i < edges; ++i) {
    const Eigen::Vector2d& a = polyline[i];
    const Eigen::Vector2d& b = polyline[(i + 1) % n];
    const int pieces = std::max(1, static_cast<int>(std::ceil((b - a).norm() / max_piece_m)));
    for (int k = 0; k < pieces; ++k) p.push_back(a + (b - a) * (static_cast<double>(k) / pieces));
  }
  if (!closed) p.push_back(polyline.back());
  for (int iteration = 0; iteration < 4; ++iteration) {
    std::vector<Eigen::Vector2d> q;
    const std::size_t m = p.size();
    if (!closed) q.push_back(p.front());
    for (std::size_t i = 0; i < (closed ? m : m - 1); ++i) {
      const Eigen::Vector2d& a = p[i];
      const Eigen::Vector2d& b = p[(i + 1) % m];
      q.push_back(0.75 * a + 0.25 * b);
      q.push_back(0.25 * a + 0.75 * b);
    }
    if (!closed) q.push_back(p.back());
    p = std::move(q);
  }
  // Resample by arc length, at a step that divides the whole length evenly
  // (a loop's last sample is then one step from its first: no jump at the seam).
  Route route;
  route.closed = closed;
  if (closed) p.push_back(p.front());
  double total = 0.0;
  for (std::size_t i = 0; i + 1 < p.size(); ++i) total += (p[i + 1] - p[i]).norm();
  const auto steps = std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(total / Route::kStep)));
  route.step = total / static_cast<double>(steps);
  route.points.reserve(steps + 1);
  std::size_t segment = 0;
  double segment_start = 0.0;  // arc length at p[segment]
  for (std::size_t k = 0; k < (closed ? steps : steps + 1); ++k) {
    const double s = std::min(static_cast<double>(k) * route.step, total);
    while (segment + 2 < p.size() && segment_start + (p[segment + 1] - p[segment]).norm() < s) {
      segment_start += (p[segment + 1] - p[segment]).norm();
      ++segment;
    }
    const Eigen::Vector2d d = p[segment + 1] - p[segment];
    const double len = d.norm();
    route.points.push_back(len > 0 ? Eigen::Vector2d(p[segment] + d * std::min((s - segment_start) / len, 1.0)) : p[segment]);
  }
  return route;
}

}  // namespace adit::sim
