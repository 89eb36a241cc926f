#include "adit/products/cross_sections.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>

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

// The section at chainage `s` from `points`: its slab's profile, floor,
// roof, walls and their width and height.
CrossSection measure_section(std::span<const Eigen::Vector3f> points, const slam::Trajectory& path,
                             const std::vector<double>& chainage, double s, const SectionOptions& o) {
  CrossSection c;
  c.chainage_m = s;
  c.centre = at_chainage(path, chainage, s);
  const Eigen::Vector2d d = (at_chainage(path, chainage, s + 1.0) - at_chainage(path, chainage, s - 1.0)).head<2>();
  c.width_m = c.height_m = kNaN;
  if (d.norm() < 1e-6) {  // the path stands still here: no direction to cut across
    c.across.setZero();
    return c;
  }
  const Eigen::Vector2d along = d.normalized();
  c.across = Eigen::Vector2d(-along.y(), along.x());
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Vector2d r = p.head<2>().cast<double>() - c.centre.head<2>();
    if (std::abs(r.dot(along)) > o.slab_m) continue;
    const double u = r.dot(c.across);
    if (std::abs(u) > o.max_half_width_m) continue;
    c.profile.emplace_back(static_cast<float>(u), p.z());
  }
  std::vector<double> below, above;
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
  std::vector<double> left, right;
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
  return c;
}

// Whether both walls of `c` run on: the sections regular_span_m before and
// after it put them within wall_tolerance_m of its own (measured in each
// section's own frame: on a bend the path's centre line keeps its offset).
bool walls_run_on(std::span<const Eigen::Vector3f> points, const slam::Trajectory& path,
                  const std::vector<double>& chainage, const CrossSection& c, const SectionOptions& o) {
  if (!std::isfinite(c.width_m)) return false;
  for (const double side : {-o.regular_span_m, o.regular_span_m}) {
    const CrossSection n = measure_section(points, path, chainage, c.chainage_m + side, o);
    if (!(std::abs(n.left_u - c.left_u) <= o.wall_tolerance_m && std::abs(n.right_u - c.right_u) <= o.wall_tolerance_m))
      return false;
  }
  return true;
}

}  // namespace

std::vector<CrossSection> cut_sections(std::span<const Eigen::Vector3f> points, const slam::Trajectory& path,
                                       const SectionOptions& o) {
  std::vector<CrossSection> out;
  if (path.size() < 2 || o.interval_m <= 0) return out;
  std::vector<double> chainage(path.size(), 0.0);
  for (std::size_t i = 1; i < path.size(); ++i)
    chainage[i] = chainage[i - 1] + (path.poses[i].translation() - path.poses[i - 1].translation()).head<2>().norm();
  const bool shifting = o.max_shift_m > 0.0 && o.shift_step_m > 0.0;
  // The offsets tried, nearest first: 0, +step, -step, +2 step, ...
  std::vector<double> offsets{0.0};
  for (double k = o.shift_step_m; shifting && k <= o.max_shift_m + 1e-9; k += o.shift_step_m) {
    offsets.push_back(k);
    offsets.push_back(-k);
  }
  // A station's section, and those around it, see only the points within
  // this horizontal reach of its nominal place.
  const double reach = o.max_half_width_m + o.max_shift_m + o.regular_span_m + 1.0;
  std::vector<Eigen::Vector3f> near;
  for (double s = o.interval_m; s < chainage.back() - 1.0; s += o.interval_m) {
    const Eigen::Vector3d nominal = at_chainage(path, chainage, s);
    near.clear();
    for (const Eigen::Vector3f& p : points)
      if ((p.head<2>().cast<double>() - nominal.head<2>()).squaredNorm() <= reach * reach) near.push_back(p);
    std::optional<CrossSection> chosen, nominal_section;
    for (const double offset : offsets) {
      const double at = s + offset;
      if (at <= 0.0 || at >= chainage.back()) continue;
      CrossSection c = measure_section(near, path, chainage, at, o);
      if (!shifting || walls_run_on(near, path, chainage, c, o)) {
        c.shift_m = offset;
        chosen = std::move(c);
        break;
      }
      if (offset == 0.0) nominal_section = std::move(c);
    }
    if (!chosen) {  // the walls break everywhere within reach: the nominal section, without its width
      chosen = std::move(nominal_section);
      chosen->walls_regular = false;
      chosen->width_m = kNaN;
    }
    if (chosen->across.squaredNorm() == 0.0) continue;
    chosen->id = static_cast<int>(out.size()) + 1;
    out.push_back(std::move(*chosen));
  }
  return out;
}

std::uintmax_t write_section_svg(const std::filesystem::path& file, const CrossSection& s, const SectionOptions& o) {
  Plot plot;
  plot.title = fmt::format("Section {} at {:.1f} m along the path", s.id, s.chainage_m);
  if (s.shift_m != 0.0) plot.title += fmt::format(" (moved {:+.1f} m to where the walls run on)", s.shift_m);
  if (!s.walls_regular) plot.title += fmt::format(" (width not given: the walls break within {:g} m)", o.max_shift_m);
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
