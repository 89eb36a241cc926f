#include "adit/eval/georeference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <set>
#include <unordered_map>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::eval {
namespace {

constexpr double kRelativeMatchTolerance = 0.002;  // the map's drift grows with distance
constexpr std::size_t kMinFitPoints = 3;

struct Pairs {
  std::vector<std::size_t> control;  // index into ControlFile::points
  std::vector<std::size_t> target;   // index into targets
};

// The level fit: a turn about the vertical only, the 2D case of Umeyama's
// closed form on E, N (theta = atan2 of the summed cross and dot products of
// the centred points), and H by the mean difference; the scale, when fitted,
// from E, N and used for H too.
std::optional<Similarity> level_fit(const std::vector<Eigen::Vector3d>& map, const std::vector<Eigen::Vector3d>& site,
                                    const std::vector<std::size_t>& use, bool with_scale) {
  if (use.size() < 2) return std::nullopt;
  Eigen::Vector3d mean_map = Eigen::Vector3d::Zero(), mean_site = Eigen::Vector3d::Zero();
  for (const std::size_t i : use) {
    mean_map += map[i];
    mean_site += site[i];
  }
  mean_map /= static_cast<double>(use.size());
  mean_site /= static_cast<double>(use.size());
  double dot = 0.0, cross = 0.0, spread = 0.0;
  for (const std::size_t i : use) {
    const Eigen::Vector2d a = (map[i] - mean_map).head<2>(), b = (site[i] - mean_site).head<2>();
    dot += a.dot(b);
    cross += a.x() * b.y() - a.y() * b.x();
    spread += a.squaredNorm();
  }
  if (spread < 1e-12) return std::nullopt;  // the points coincide in plan: no heading
  const double theta = std::atan2(cross, dot);
  Similarity f;
  f.rotation = Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  f.scale = with_scale ? std::hypot(dot, cross) / spread : 1.0;
  f.translation = mean_site - f.scale * (f.rotation * mean_map);
  return f;
}

std::optional<Similarity> fit_subset(const std::vector<Eigen::Vector3d>& map, const std::vector<Eigen::Vector3d>& site,
                                     const std::vector<std::size_t>& use, bool with_scale, bool level = false) {
  if (level) return level_fit(map, site, use, with_scale);
  Eigen::Matrix3Xd from(3, static_cast<Eigen::Index>(use.size()));
  Eigen::Matrix3Xd to(3, static_cast<Eigen::Index>(use.size()));
  for (std::size_t k = 0; k < use.size(); ++k) {
    from.col(static_cast<Eigen::Index>(k)) = map[use[k]];
    to.col(static_cast<Eigen::Index>(k)) = site[use[k]];
  }
  return umeyama_fit(from, to, with_scale);
}

std::vector<std::size_t> all_of(std::size_t n) {
  std::vector<std::size_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = i;
  return v;
}

double median_residual(const std::vector<Eigen::Vector3d>& map, const std::vector<Eigen::Vector3d>& site,
                       const Similarity& fit) {
  std::vector<double> r;
  for (std::size_t i = 0; i < map.size(); ++i) r.push_back((site[i] - fit.apply(map[i])).norm());
  std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2), r.end());
  return r[r.size() / 2];
}

// The angle between the map's up (z) and the site's up (H) after the fit.
double tilt_deg(const Similarity& fit) {
  return std::acos(std::clamp(fit.rotation(2, 2), -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

std::string where_line(const ControlFile& file, std::size_t line) {
  return line == 0 ? file.name.string() : fmt::format("{}:{}", file.name.string(), line);
}

Pairs match_ids(const ControlFile& control, const std::vector<Target>& targets, MatchBy match) {
  std::unordered_map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < targets.size(); ++i) index.emplace(targets[i].id, i);
  Pairs pairs;
  const ControlPoint* unknown = nullptr;
  for (std::size_t c = 0; c < control.points.size(); ++c) {
    const auto it = index.find(control.points[c].id);
    if (it == index.end()) {
      if (unknown == nullptr) unknown = &control.points[c];
      continue;
    }
    pairs.control.push_back(c);
    pairs.target.push_back(it->second);
  }
  if (unknown != nullptr && (match == MatchBy::id || !pairs.control.empty()))
    throw InputError(where_line(control, unknown->line), "id",
                     fmt::format("'{}' is not a target id ({} of {} control ids are; --match geometry ignores ids)",
                                 unknown->id, pairs.control.size(), control.points.size()));
  return pairs;
}

Pairs from_assignment(const std::vector<int>& assignment) {
  Pairs pairs;
  for (std::size_t c = 0; c < assignment.size(); ++c)
    if (assignment[c] >= 0) {
      pairs.control.push_back(c);
      pairs.target.push_back(static_cast<std::size_t>(assignment[c]));
    }
  return pairs;
}

std::size_t matched_count(const std::vector<int>& assignment) {
  return static_cast<std::size_t>(std::count_if(assignment.begin(), assignment.end(), [](int t) { return t >= 0; }));
}

// A length ratio that says feet were read as metres (or metres as feet).
void check_units(const ControlFile& control, double scale) {
  constexpr double kFeet = 1.0 / 0.3048;
  if (std::abs(scale / kFeet - 1.0) < 0.005)
    throw InputError(control.name.string(), "units",
                     fmt::format("the control points lie {:.4f} times as far apart as the targets: the file looks to be "
                                 "in feet; say --units ft (or usft)",
                                 scale));
  if (std::abs(scale * kFeet - 1.0) < 0.005)
    throw InputError(control.name.string(), "units",
                     fmt::format("the control points lie {:.4f} times as far apart as the targets: the file looks to be "
                                 "in metres, not the feet stated; say --units m",
                                 scale));
}

}  // namespace

std::vector<int> match_by_geometry(const std::vector<Eigen::Vector3d>& control,
                                   const std::vector<Eigen::Vector3d>& targets, double tolerance_m) {
  const std::size_t n = control.size(), m = targets.size();
  std::vector<int> best(n, -1);
  if (n < 2 || m < 2) return best;
  const auto dc = [&](std::size_t a, std::size_t b) { return (control[a] - control[b]).norm(); };
  const auto dt = [&](std::size_t i, std::size_t j) { return (targets[i] - targets[j]).norm(); };
  const auto agree = [&](double d_control, double d_target) {
    const double e = std::abs(d_control - d_target);
    return e <= tolerance_m + kRelativeMatchTolerance * d_control ? e : -1.0;
  };
  std::size_t best_count = 0;
  double best_error = std::numeric_limits<double>::infinity();
  std::vector<int> assign(n);
  std::vector<char> taken(m);
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = a + 1; b < n; ++b)
      for (std::size_t i = 0; i < m; ++i)
        for (std::size_t j = 0; j < m; ++j) {
          if (i == j) continue;
          const double e0 = agree(dc(a, b), dt(i, j));
          if (e0 < 0.0) continue;
          std::fill(assign.begin(), assign.end(), -1);
          std::fill(taken.begin(), taken.end(), 0);
          assign[a] = static_cast<int>(i);
          assign[b] = static_cast<int>(j);
          taken[i] = taken[j] = 1;
          std::size_t count = 2;
          double error = e0;
          for (std::size_t c = 0; c < n; ++c) {
            if (assign[c] >= 0) continue;
            int pick = -1;
            double pick_error = std::numeric_limits<double>::infinity();
            for (std::size_t k = 0; k < m; ++k) {
              if (taken[k]) continue;
              double sum = 0.0;
              bool ok = true;
              for (std::size_t x = 0; x < n && ok; ++x) {
                if (assign[x] < 0) continue;
                const double e = agree(dc(c, x), dt(k, static_cast<std::size_t>(assign[x])));
                ok = e >= 0.0;
                sum += e;
              }
              if (ok && sum < pick_error) {
                pick = static_cast<int>(k);
                pick_error = sum;
              }
            }
            if (pick < 0) continue;
            assign[c] = pick;
            taken[static_cast<std::size_t>(pick)] = 1;
            ++count;
            error += pick_error;
          }
          if (count > best_count || (count == best_count && error < best_error)) {
            best = assign;
            best_count = count;
            best_error = error;
          }
          if (best_count == n && best_error <= tolerance_m) return best;  // every point, closely: done
        }
  return best;
}

Georeference georeference(const ControlFile& control, const std::vector<Target>& targets, const GeorefOptions& options) {
  const std::string file = control.name.string();
  Georeference result;

  // 1. Which target is which control point.
  Pairs pairs;
  if (options.match != MatchBy::geometry) pairs = match_ids(control, targets, options.match);
  if (!pairs.control.empty()) {
    result.matched_by = "id";
  } else {
    result.matched_by = "geometry";
    std::vector<Eigen::Vector3d> c, t;
    for (const ControlPoint& p : control.points) c.push_back(p.enh);
    for (const Target& p : targets) t.push_back(p.position);
    const std::vector<int> assignment = match_by_geometry(c, t, options.match_tolerance_m);
    if (matched_count(assignment) < kMinFitPoints) {
      // Feet read as metres (or the reverse) change every distance: try both.
      for (const double ratio : {0.3048, 1.0 / 0.3048}) {
        std::vector<Eigen::Vector3d> scaled;
        for (const Eigen::Vector3d& p : c) scaled.push_back(p * ratio);
        if (matched_count(match_by_geometry(scaled, t, options.match_tolerance_m)) >= kMinFitPoints)
          check_units(control, 1.0 / ratio);
      }
    }
    pairs = from_assignment(assignment);
    for (std::size_t k = 0; k < assignment.size(); ++k)
      if (assignment[k] < 0) result.unmatched.push_back(control.points[k].id);
  }
  if (pairs.control.size() < kMinFitPoints) {
    std::string which;
    for (std::size_t k = 0; k < pairs.control.size(); ++k)
      which += fmt::format("{}{} (line {})", k == 0 ? ": " : ", ", control.points[pairs.control[k]].id,
                           control.points[pairs.control[k]].line);
    throw InputError(file, "", fmt::format("{} control point{} matched a target by {}{}; the fit needs at least 3",
                                           pairs.control.size(), pairs.control.size() == 1 ? "" : "s",
                                           result.matched_by, which));
  }
  std::vector<Eigen::Vector3d> map, site;
  for (std::size_t k = 0; k < pairs.control.size(); ++k) {
    map.push_back(targets[pairs.target[k]].position);
    site.push_back(control.points[pairs.control[k]].enh);
  }
  const std::size_t n = map.size();

  // 2. Gross problems: units, swapped columns, points that do not fit at all.
  const auto scaled = fit_subset(map, site, all_of(n), true);
  if (!scaled) throw InputError(file, "", "the matched control points lie on one line: the rotation about it is not determined");
  check_units(control, scaled->scale);
  const auto first = fit_subset(map, site, all_of(n), options.with_scale, options.level);
  if (!first) throw InputError(file, "", "the matched control points lie on one line: the rotation about it is not determined");
  const double median = median_residual(map, site, *first);
  const double tilt = tilt_deg(*first);
  if (median > options.match_tolerance_m || tilt > options.max_tilt_deg) {
    // E and N exchanged mirror the points: a rigid fit cannot follow, or (the
    // targets lying near one level) follows by turning the map upside down.
    std::vector<Eigen::Vector3d> mirrored = site;
    for (Eigen::Vector3d& p : mirrored) std::swap(p.x(), p.y());
    const auto swapped = fit_subset(map, mirrored, all_of(n), options.with_scale);  // a mirror needs the full fit
    const std::size_t line = control.header_line != 0 ? control.header_line : control.points[pairs.control[0]].line;
    if (swapped && median_residual(map, mirrored, *swapped) <= options.match_tolerance_m &&
        tilt_deg(*swapped) <= options.max_tilt_deg)
      throw InputError(where_line(control, line), "E,N",
                       fmt::format("E and N look swapped: the fit leaves a median residual of {:.3f} m and tilts the "
                                   "map {:.1f} deg as read, {:.3f} m and {:.1f} deg with them exchanged; fix the {}",
                                   median, tilt, median_residual(map, mirrored, *swapped), tilt_deg(*swapped),
                                   control.header_line != 0 ? "header" : "columns (or add a header: id,N,E,H)"));
    if (median > options.match_tolerance_m)
      throw InputError(file, "",
                       fmt::format("the control points do not fit their targets (median residual {:.3f} m over {} "
                                   "points, matched by {}): wrong ids, another site, or a wrong target list?",
                                   median, n, result.matched_by));
    throw InputError(file, "",
                     fmt::format("the fit tilts the map's vertical by {:.1f} deg (at most {:.1f} expected: the map's z "
                                 "is up): wrong matches, or H not a height?",
                                 tilt, options.max_tilt_deg));
  }

  // 3. Data snooping: leave out the worst leave-one-out residual while it is too large.
  std::vector<std::size_t> in_fit = all_of(n);
  const auto leave_one_out = [&](std::size_t i) -> std::optional<Eigen::Vector3d> {
    std::vector<std::size_t> rest;
    for (const std::size_t k : in_fit)
      if (k != i) rest.push_back(k);
    if (rest.size() < kMinFitPoints) return std::nullopt;
    const auto fit = fit_subset(map, site, rest, options.with_scale, options.level);
    if (!fit) return std::nullopt;
    return Eigen::Vector3d(site[i] - fit->apply(map[i]));
  };
  while (in_fit.size() > kMinFitPoints) {
    std::size_t worst = n;
    double worst_distance = options.tolerance_m;
    for (const std::size_t i : in_fit)
      if (const auto d = leave_one_out(i); d && d->norm() > worst_distance) {
        worst = i;
        worst_distance = d->norm();
      }
    if (worst == n) break;
    in_fit.erase(std::find(in_fit.begin(), in_fit.end(), worst));
  }
  const auto fit = fit_subset(map, site, in_fit, options.with_scale, options.level);
  if (!fit) throw InputError(file, "", "the control points left in the fit lie on one line");
  result.fit = *fit;

  // 4. The table: residuals against the final fit, and each point's check residual.
  double sum2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const ControlPoint& p = control.points[pairs.control[i]];
    ControlResidual r;
    r.id = p.id;
    r.target_id = targets[pairs.target[i]].id;
    r.line = p.line;
    r.delta = site[i] - fit->apply(map[i]);
    r.distance = r.delta.norm();
    r.in_fit = std::find(in_fit.begin(), in_fit.end(), i) != in_fit.end();
    r.loo_delta = r.in_fit ? leave_one_out(i) : std::optional<Eigen::Vector3d>(r.delta);
    r.flagged = !r.in_fit || r.distance > options.tolerance_m || (r.loo_delta && r.loo_delta->norm() > options.tolerance_m);
    if (r.in_fit) sum2 += r.distance * r.distance;
    result.points.push_back(std::move(r));
  }
  result.rms_m = std::sqrt(sum2 / static_cast<double>(in_fit.size()));
  return result;
}

}  // namespace adit::eval
