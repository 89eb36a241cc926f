#include "adit/products/top_view.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "adit/products/raster_image.hpp"

namespace adit::products {

double nice_length(double at_most) {
  if (!(at_most > 0)) return 0.0;
  const double p = std::pow(10.0, std::floor(std::log10(at_most)));
  for (const double m : {5.0, 2.0, 1.0})
    if (m * p <= at_most) return m * p;
  return p;
}

TopViewReport write_top_view(const std::filesystem::path& file, std::span<const Eigen::Vector3f> points,
                             const GroundModel& ground, const slam::Trajectory& path,
                             std::span<const Eigen::Vector3d> targets, const TopViewOptions& o) {
  TopViewReport r;
  double lo_x = std::numeric_limits<double>::max(), lo_y = lo_x, hi_x = -lo_x, hi_y = -lo_x;
  for (const Eigen::Vector3f& p : points) {
    lo_x = std::min(lo_x, double{p.x()});
    lo_y = std::min(lo_y, double{p.y()});
    hi_x = std::max(hi_x, double{p.x()});
    hi_y = std::max(hi_y, double{p.y()});
  }
  if (points.empty()) lo_x = lo_y = hi_x = hi_y = 0.0;
  r.pixel_m = std::max(o.pixel_m, std::max(hi_x - lo_x, hi_y - lo_y) / o.max_side_px);
  const int margin = 10, legend = 70;
  const int map_w = static_cast<int>(std::ceil((hi_x - lo_x) / r.pixel_m)) + 1;
  const int map_h = static_cast<int>(std::ceil((hi_y - lo_y) / r.pixel_m)) + 1;
  r.width = std::max(map_w + 2 * margin, 420);
  r.height = map_h + 2 * margin + legend;
  RasterImage image(r.width, r.height, {255, 255, 255});
  const auto px = [&](double x) { return margin + (x - lo_x) / r.pixel_m; };
  const auto py = [&](double y) { return margin + (hi_y - y) / r.pixel_m; };
  // Highest point below the roof band over each pixel.
  std::vector<float> top(static_cast<std::size_t>(map_w) * map_h, -std::numeric_limits<float>::infinity());
  for (const Eigen::Vector3f& p : points) {
    const double h = p.z() - ground.height_at(p.x(), p.y());
    if (h > o.band_high_m) continue;
    const int c = static_cast<int>((p.x() - lo_x) / r.pixel_m), row = static_cast<int>((hi_y - p.y()) / r.pixel_m);
    if (c < 0 || row < 0 || c >= map_w || row >= map_h) continue;
    float& t = top[static_cast<std::size_t>(row) * map_w + c];
    t = std::max(t, static_cast<float>(h));
  }
  for (int row = 0; row < map_h; ++row)
    for (int c = 0; c < map_w; ++c) {
      const float h = top[static_cast<std::size_t>(row) * map_w + c];
      if (std::isfinite(h)) image.set(margin + c, margin + row, viridis(h / o.band_high_m));
    }
  for (std::size_t i = 1; i < path.size(); ++i) {
    const Eigen::Vector3d& a = path.poses[i - 1].translation();
    const Eigen::Vector3d& b = path.poses[i].translation();
    image.line(px(a.x()), py(a.y()), px(b.x()), py(b.y()), {220, 30, 30}, 2);
  }
  if (!path.empty()) image.disc(px(path.poses.front().translation().x()), py(path.poses.front().translation().y()), 5, {30, 160, 30});
  for (const Eigen::Vector3d& t : targets) {
    image.disc(px(t.x()), py(t.y()), 6, {255, 255, 255});
    image.disc(px(t.x()), py(t.y()), 4, {220, 0, 220});
  }
  // Scale bar: a fifth of the width or less, ticks at its ends and middle.
  const int base = r.height - legend + 20;
  r.scale_bar_m = nice_length(0.2 * (r.width - 2 * margin) * r.pixel_m);
  const int bar = static_cast<int>(std::lround(r.scale_bar_m / r.pixel_m));
  image.rect(margin, base + 10, margin + bar, base + 13, {0, 0, 0});
  for (const int x : {margin, margin + bar / 2, margin + bar}) image.rect(x - 1, base + 4, x + 1, base + 19, {0, 0, 0});
  image.text(margin + bar + 10, base + 5, fmt::format("{:g} m", r.scale_bar_m), {0, 0, 0}, 2);
  // Colour scale: height above the ground.
  const int cx = r.width - margin - 160;
  image.text(cx - 30, base + 5, "h", {0, 0, 0}, 2);
  for (int k = 0; k <= 120; ++k) image.rect(cx + k, base + 4, cx + k, base + 18, viridis(k / 120.0));
  image.text(cx - 4, base + 24, "0", {0, 0, 0}, 2);
  image.text(cx + 100, base + 24, fmt::format("{:g} m", o.band_high_m), {0, 0, 0}, 2);
  r.bytes = image.write_png(file);
  return r;
}

}  // namespace adit::products
