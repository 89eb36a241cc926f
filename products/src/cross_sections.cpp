#include "adit/products/cross_sections.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/products/svg_plot.hpp"

namespace adit::products {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double median(std::vector<double>& v) {
  if (v.empty()) return kNaN;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// The sensor's horizontal position at path length `s` (chainage), linear between poses.
Eigen::Vector3d at_chainage(const slam::Trajectory& path, const std::vector<double>& chainage, double s) {
  const auto it = std::lower_bound(chainage.begin(), chainage.end(), s);
  if (it == chainage.begin()) return path.poses.front().translation();
  if (it == chainage.end()) return path.poses.back().translation();
  const std::size_t j = static_cast<std::size_t>(it - chainage.begin());
  const double a = (s - chainage[j - 1]) / std::max(1e-9, chainage[j] - chainage[j - 1]);
  return (1 - a) * path.poses[j - 1].translation() + a * path.poses[j].translation();
}

}  // namespace

std::vector<CrossSection> cut_sections(std::span<const Eigen::Vector3f> points, const slam::Trajectory& path,
                                       const SectionOptions& o) {
  std::vector<CrossSection> out;
  if (path.size() < 2 || o.interval_m <= 0) return out;
  std::vector<double> chainage(path.size(), 0.0);
  for (std::size_t i = 1; i < path.size(); ++i)
    chainage[i] = chainage[i - 1] + (path.poses[i].translation() - path.poses[i - 1].translation()).head<2>().norm();
  std::vector<double> left, right, below, above;
  for (double s = o.interval_m; s < chainage.back() - 1.0; s += o.interval_m) {
    CrossSection c;
    c.id = static_cast<int>(out.size()) + 1;
    c.chainage_m = s;
    c.centre = at_chainage(path, chainage, s);
    const Eigen::Vector2d d = (at_chainage(path, chainage, s + 1.0) - at_chainage(path, chainage, s - 1.0)).head<2>();
    if (d.norm() < 1e-6) continue;
    const Eigen::Vector2d along = d.normalized();
    c.across = Eigen::Vector2d(-along.y(), along.x());
    for (const Eigen::Vector3f& p : points) {
      const Eigen::Vector2d r = p.head<2>().cast<double>() - c.centre.head<2>();
      if (std::abs(r.dot(along)) > o.slab_m) continue;
      const double u = r.dot(c.across);
      if (std::abs(u) > o.max_half_width_m) continue;
      c.profile.emplace_back(static_cast<float>(u), p.z());
    }
    below.clear();
    above.clear();
    for (const Eigen::Vector2f& q : c.profile) {
      if (std::abs(q.x()) > 0.75) continue;
      (q.y() < c.centre.z() - 0.3 ? below : above).push_back(q.y());
    }
    above.erase(std::remove_if(above.begin(), above.end(), [&](double z) { return z < c.centre.z() + 0.3; }), above.end());
    c.floor_z = median(below);
    c.roof_z = median(above);
    c.height_m = c.roof_z - c.floor_z;
    // Width: the innermost wall points each side at the height, their median within 0.3 m of the innermost.
    const double zw = c.floor_z + o.width_at_m;
    left.clear();
    right.clear();
    double inner_left = std::numeric_limits<double>::max(), inner_right = -std::numeric_limits<double>::max();
    for (const Eigen::Vector2f& q : c.profile) {
      if (!std::isfinite(zw) || std::abs(q.y() - zw) > o.band_m) continue;
      if (q.x() > 0) inner_left = std::min(inner_left, double{q.x()});
      else inner_right = std::max(inner_right, double{q.x()});
    }
    for (const Eigen::Vector2f& q : c.profile) {
      if (!std::isfinite(zw) || std::abs(q.y() - zw) > o.band_m) continue;
      if (q.x() > 0 && q.x() < inner_left + 0.3) left.push_back(q.x());
      if (q.x() <= 0 && q.x() > inner_right - 0.3) right.push_back(q.x());
    }
    c.left_u = median(left);
    c.right_u = median(right);
    c.width_m = c.left_u - c.right_u;
    out.push_back(std::move(c));
  }
  return out;
}

std::uintmax_t write_section_svg(const std::filesystem::path& file, const CrossSection& s, const SectionOptions& o) {
  Plot plot;
  plot.title = fmt::format("Section {} at {:.1f} m along the path", s.id, s.chainage_m);
  plot.x_label = "across the path, left + (m)";
  plot.y_label = "height (m, map frame)";
  plot.equal_axes = true;
  plot.width = 900;
  plot.height = 700;
  PlotSeries cloud{"map points", "#5a5a5a", SeriesStyle::points, {}, {}};
  cloud.point_radius = 1.2;
  for (const Eigen::Vector2f& q : s.profile) {
    cloud.x.push_back(q.x());
    cloud.y.push_back(q.y());
  }
  plot.series.push_back(std::move(cloud));
  const std::string dim = "#d62728";
  if (std::isfinite(s.width_m)) {
    const double zw = s.floor_z + o.width_at_m;
    plot.series.push_back({fmt::format("width at {:g} m", o.width_at_m), dim, SeriesStyle::line, {s.right_u, s.left_u}, {zw, zw}, 2.0});
    plot.texts.push_back({0.5 * (s.left_u + s.right_u), zw, fmt::format("W {:.2f} m", s.width_m), dim, "middle", -8});
  }
  if (std::isfinite(s.height_m)) {
    plot.series.push_back({"height", "#1f77b4", SeriesStyle::line, {0.0, 0.0}, {s.floor_z, s.roof_z}, 2.0});
    plot.texts.push_back({0.0, 0.5 * (s.floor_z + s.roof_z), fmt::format("H {:.2f} m", s.height_m), "#1f77b4", "start", 0});
    plot.texts.back().x = 0.15;
  }
  plot.series.push_back({"sensor", "#2ca02c", SeriesStyle::points, {0.0}, {s.centre.z()}});
  write_svg(file, plot);
  return std::filesystem::file_size(file);
}

void write_sections_csv(const std::filesystem::path& file, std::span<const CrossSection> sections) {
  std::ofstream out(file);
  if (!out) throw InputError(file.string(), "", "cannot open for writing");
  out << "id,chainage_m,x,y,z,across_x,across_y,floor_z,roof_z,width_m,height_m\n";
  for (const CrossSection& s : sections)
    out << fmt::format("{},{:.3f},{:.4f},{:.4f},{:.4f},{:.6f},{:.6f},{:.4f},{:.4f},{:.4f},{:.4f}\n", s.id, s.chainage_m,
                       s.centre.x(), s.centre.y(), s.centre.z(), s.across.x(), s.across.y(), s.floor_z, s.roof_z,
                       s.width_m, s.height_m);
  if (!out) throw InputError(file.string(), "", "write failed");
}

}  // namespace adit::products
