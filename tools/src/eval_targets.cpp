// adit eval targets: map targets against total-station targets.

#include <limits>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/common/log.hpp"
#include "adit/eval/pose_error.hpp"
#include "adit/eval/targets.hpp"
#include "adit/eval/targets_io.hpp"
#include "eval_commands.hpp"
#include "adit/products/svg_plot.hpp"

namespace adit::tools {

using products::kColorEstimate;
using products::kColorReference;
using products::kColorSecond;
using products::Plot;
using products::PlotSeries;
using products::SeriesStyle;
using products::write_svg;
namespace {

using namespace adit::slam;
using namespace adit::eval;

std::vector<std::string> split_ids(const std::string& text) {
  std::vector<std::string> ids;
  std::size_t start = 0;
  while (start <= text.size() && !text.empty()) {
    std::size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    std::string id = text.substr(start, end - start);
    id.erase(0, id.find_first_not_of(" \t"));
    id.erase(id.find_last_not_of(" \t") + 1);
    if (id.empty()) throw InputError("", "--control", fmt::format("empty id in '{}'", text));
    ids.push_back(id);
    start = end + 1;
  }
  return ids;
}

nlohmann::json point_json(const PointError& p) {
  return {{"id", p.id},        {"control", p.control}, {"dx", p.delta.x()},
          {"dy", p.delta.y()}, {"dz", p.delta.z()},    {"distance", p.distance}};
}

nlohmann::json report_json(const TargetsEvalOptions& o, const TargetReport& r) {
  nlohmann::json j;
  j["truth"] = o.truth;
  j["map"] = o.map;
  j["unmatched"] = r.unmatched;
  nlohmann::json distances = nlohmann::json::array();
  for (const DistanceError& d : r.distances)
    distances.push_back({{"from", d.from},
                         {"to", d.to},
                         {"true_distance", d.true_distance},
                         {"map_distance", d.map_distance},
                         {"error", d.error},
                         {"rate", d.rate}});
  j["relative"] = {{"pairs", distances}, {"error_rmse", r.distance_rmse}, {"rate_rmse", r.rate_rmse}};
  nlohmann::json rotation = nlohmann::json::array();
  for (int row = 0; row < 3; ++row)
    rotation.push_back({r.fit.rotation(row, 0), r.fit.rotation(row, 1), r.fit.rotation(row, 2)});
  nlohmann::json points = nlohmann::json::array();
  for (const PointError& p : r.points) points.push_back(point_json(p));
  j["absolute"] = {
      {"fit",
       {{"kind", o.scale ? "similarity" : "rigid"},
        {"rotation", rotation},
        {"translation", {r.fit.translation.x(), r.fit.translation.y(), r.fit.translation.z()}},
        {"scale", r.fit.scale}}},
      {"points", points},
      {"rmse", {{"x", r.rmse_xyz.x()}, {"y", r.rmse_xyz.y()}, {"z", r.rmse_xyz.z()}, {"distance", r.rmse_distance}}}};
  nlohmann::json loo = nlohmann::json::array();
  for (const LeaveOneOut& l : r.leave_one_out)
    loo.push_back(l.error ? point_json(*l.error) : nlohmann::json{{"id", l.id}, {"distance", nullptr}});
  j["leave_one_out"] = loo;
  return j;
}

void print_report(const TargetsEvalOptions& o, const TargetReport& r) {
  fmt::print("truth {}  map {}\n", o.truth, o.map);
  if (!r.unmatched.empty()) fmt::print("in one file only (ignored): {}\n", fmt::join(r.unmatched, ", "));
  fmt::print("\n(a) distances between consecutive targets, delta = D_true - D_map\n");
  fmt::print("{:<10} {:<10} {:>12} {:>12} {:>10} {:>10}\n", "from", "to", "D_true (m)", "D_map (m)", "delta (m)",
             "rate (%)");
  for (const DistanceError& d : r.distances)
    fmt::print("{:<10} {:<10} {:>12.4f} {:>12.4f} {:>10.4f} {:>10.4f}\n", d.from, d.to, d.true_distance, d.map_distance,
               d.error, 100.0 * d.rate);
  fmt::print("{:<46} {:>10.4f} {:>10.4f}\n", "RMSE", r.distance_rmse, 100.0 * r.rate_rmse);

  fmt::print("\n(b) residuals true - fitted map after a {} fit on the control targets (*)\n",
             o.scale ? "similarity" : "rigid");
  fmt::print("    fit: rotation {:.4f} deg, translation ({:.4f}, {:.4f}, {:.4f}) m, scale {:.8f}\n",
             rad_to_deg(rotation_angle(r.fit.rotation)), r.fit.translation.x(), r.fit.translation.y(),
             r.fit.translation.z(), r.fit.scale);
  fmt::print("{:<12} {:>10} {:>10} {:>10} {:>10}\n", "target", "dX (m)", "dY (m)", "dZ (m)", "dist (m)");
  for (const PointError& p : r.points)
    fmt::print("{:<12} {:>10.4f} {:>10.4f} {:>10.4f} {:>10.4f}\n", p.id + (p.control ? " *" : ""), p.delta.x(),
               p.delta.y(), p.delta.z(), p.distance);
  fmt::print("{:<12} {:>10.4f} {:>10.4f} {:>10.4f} {:>10.4f}\n", "RMSE", r.rmse_xyz.x(), r.rmse_xyz.y(), r.rmse_xyz.z(),
             r.rmse_distance);

  fmt::print("\n(c) each target left out of the fit\n");
  fmt::print("{:<12} {:>10} {:>10} {:>10} {:>10}\n", "target", "dX (m)", "dY (m)", "dZ (m)", "dist (m)");
  for (const LeaveOneOut& l : r.leave_one_out) {
    if (l.error)
      fmt::print("{:<12} {:>10.4f} {:>10.4f} {:>10.4f} {:>10.4f}\n", l.id, l.error->delta.x(), l.error->delta.y(),
                 l.error->delta.z(), l.error->distance);
    else
      fmt::print("{:<12} {:>43}\n", l.id, "n/a (the rest cannot fix a fit)");
  }
}

void write_plot(const std::string& path, const TargetReport& r) {
  Plot plot{"Target errors", "target (* = control)", "distance error (mm)", {}, {}};
  PlotSeries fitted{"after the fit", kColorSecond, SeriesStyle::bars, {}, {}};
  PlotSeries left_out{"left out of the fit", kColorEstimate, SeriesStyle::bars, {}, {}};
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    plot.categories.push_back(r.points[i].id + (r.points[i].control ? " *" : ""));
    fitted.y.push_back(1000.0 * r.points[i].distance);
    const auto& loo = r.leave_one_out[i].error;
    left_out.y.push_back(loo ? 1000.0 * loo->distance : std::numeric_limits<double>::quiet_NaN());
  }
  plot.series = {fitted, left_out};
  write_svg(path, plot);
}

}  // namespace

void run_eval_targets(const TargetsEvalOptions& o) {
  const std::vector<Target> truth = read_targets_csv(o.truth);
  const std::vector<Target> map = read_targets_csv(o.map);
  const TargetReport report = evaluate_targets(truth, map, split_ids(o.control), o.scale);
  if (o.json)
    fmt::print("{}\n", report_json(o, report).dump(2));
  else
    print_report(o, report);
  if (!o.svg.empty()) write_plot(o.svg, report);
}

}  // namespace adit::tools
