#include <cmath>

#include "adit/sim/scene.hpp"

namespace adit::sim {

double Route::length() const { return points.size() < 2 ? 0.0 : kStep * static_cast<double>(points.size() - (closed ? 0 : 1)); }

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
  // Resample by arc length.
  Route route;
  route.closed = closed;
  if (closed) p.push_back(p.front());
  double carried = 0.0;  // arc length from the last emitted sample to the current vertex
  route.points.push_back(p.front());
  for (std::size_t i = 0; i + 1 < p.size(); ++i) {
    const Eigen::Vector2d d = p[i + 1] - p[i];
    const double len = d.norm();
    double s = Route::kStep - carried;
    while (s <= len) {
      route.points.push_back(p[i] + d * (s / len));
      s += Route::kStep;
    }
    carried = len - (s - Route::kStep);
  }
  if (closed && route.points.size() > 1 && (route.points.back() - route.points.front()).norm() < 0.5 * Route::kStep) {
    route.points.pop_back();
  }
  return route;
}

}  // namespace adit::sim
