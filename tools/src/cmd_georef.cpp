// adit georef SESSION_DIR --control FILE.csv: the session's map and trajectory
// in site coordinates, fitted on control points measured by total station on
// the targets found in the map (eval/georeference.hpp), with the residual
// table survey software prints (docs/GEOREF.md).

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/common/error.hpp"
#include "adit/eval/control_points.hpp"
#include "adit/eval/georeference.hpp"
#include "adit/eval/targets_io.hpp"
#include "adit/products/session_map.hpp"
#include "adit/protocol/map_export.hpp"
#include "adit/protocol/map_import.hpp"
#include "adit/slam/tum.hpp"
#include "commands.hpp"
#include "crs_wkt.hpp"

namespace adit::tools {
namespace {

struct GeorefCommand {
  std::string session, control, targets, out, units = "m", match = "auto";
  int epsg = 0;
  bool ply = false;
  eval::GeorefOptions options;
};

std::string check_column(const eval::ControlResidual& r) {
  return r.loo_delta ? fmt::format("{:9.3f}", r.loo_delta->norm()) : fmt::format("{:>9}", "-");
}

void print_table(const eval::Georeference& g, const GeorefCommand& c, std::size_t control_points) {
  std::size_t in_fit = 0;
  for (const auto& r : g.points) in_fit += r.in_fit ? 1 : 0;
  fmt::print("control points {}: {} of {} matched to targets by {}; {} fit on {}, tolerance {:.3f} m\n", c.control,
             g.points.size(), control_points, g.matched_by, fmt::format("{}{}", c.options.level ? "level " : "", c.options.with_scale ? "similarity" : "rigid"), in_fit,
             c.options.tolerance_m);
  fmt::print("{:<12} {:<8} {:>9} {:>9} {:>9} {:>9} {:>9}\n", "point", "target", "dE [m]", "dN [m]", "dH [m]", "3D [m]",
             "check [m]");
  for (const eval::ControlResidual& r : g.points) {
    std::string note;
    if (!r.in_fit)
      note = "  FLAGGED: left out of the fit";
    else if (r.flagged)
      note = "  FLAGGED";
    fmt::print("{:<12} {:<8} {:9.3f} {:9.3f} {:9.3f} {:9.3f} {}{}\n", r.id, r.target_id, r.delta.x(), r.delta.y(),
               r.delta.z(), r.distance, check_column(r), note);
  }
  for (const std::string& id : g.unmatched) fmt::print("{:<12} (no target matches it)\n", id);
  fmt::print("rms of the points in the fit: {:.3f} m (residual = control - fitted target; check = the same with the "
             "point left out of the fit)\n",
             g.rms_m);
  const Eigen::Matrix3d& R = g.fit.rotation;
  const double heading = std::atan2(R(1, 0), R(0, 0)) * 180.0 / std::numbers::pi;
  const double tilt = std::acos(std::clamp(R(2, 2), -1.0, 1.0)) * 180.0 / std::numbers::pi;
  fmt::print("map -> site: rotation {:.4f} deg about H (tilt {:.4f} deg), translation E {:.3f} N {:.3f} H {:.3f}, scale {:.6f}\n",
             heading, tilt, g.fit.translation.x(), g.fit.translation.y(), g.fit.translation.z(), g.fit.scale);
}

nlohmann::json to_json(const eval::Georeference& g, const GeorefCommand& c) {
  nlohmann::json points = nlohmann::json::array();
  for (const eval::ControlResidual& r : g.points)
    points.push_back({{"id", r.id},
                      {"target", r.target_id},
                      {"line", r.line},
                      {"dE", r.delta.x()},
                      {"dN", r.delta.y()},
                      {"dH", r.delta.z()},
                      {"d3", r.distance},
                      {"check_d3", r.loo_delta ? nlohmann::json(r.loo_delta->norm()) : nlohmann::json(nullptr)},
                      {"in_fit", r.in_fit},
                      {"flagged", r.flagged}});
  nlohmann::json rotation = nlohmann::json::array();
  for (int i = 0; i < 3; ++i) rotation.push_back({g.fit.rotation(i, 0), g.fit.rotation(i, 1), g.fit.rotation(i, 2)});
  return {{"control", c.control},
          {"matched_by", g.matched_by},
          {"with_scale", c.options.with_scale},
          {"level", c.options.level},
          {"tolerance_m", c.options.tolerance_m},
          {"epsg", c.epsg == 0 ? nlohmann::json(nullptr) : nlohmann::json(c.epsg)},
          {"map_to_site", {{"rotation", rotation},
                           {"translation", {g.fit.translation.x(), g.fit.translation.y(), g.fit.translation.z()}},
                           {"scale", g.fit.scale}}},
          {"rms_m", g.rms_m},
          {"points", points},
          {"unmatched", g.unmatched}};
}

void run_georef(const GeorefCommand& c) {
  const std::filesystem::path dir = c.session;
  const auto unit = eval::parse_length_unit(c.units);
  if (!unit) throw InputError("--units", "", fmt::format("'{}' is not m, ft or usft", c.units));
  eval::GeorefOptions options = c.options;
  options.match = c.match == "id" ? eval::MatchBy::id : c.match == "geometry" ? eval::MatchBy::geometry : eval::MatchBy::automatic;
  if (!(options.tolerance_m > 0.0)) throw InputError("--tolerance", "", "must be > 0");
  if (!(options.match_tolerance_m > 0.0)) throw InputError("--match-tolerance", "", "must be > 0");

  // Everything is read and checked before anything is written.
  const eval::ControlFile control = eval::read_control_points(c.control, *unit);
  const std::filesystem::path targets_file = c.targets.empty() ? dir / "products" / "targets.csv" : std::filesystem::path(c.targets);
  if (c.targets.empty() && !std::filesystem::exists(targets_file))
    throw InputError(targets_file.string(), "",
                     "no targets: run `adit targets find SESSION --out FILE` (or `adit products`) or give --targets");
  const std::vector<eval::Target> targets = eval::read_targets_csv(targets_file);
  const eval::Georeference g = eval::georeference(control, targets, options);
  const std::string wkt = c.epsg == 0 ? std::string() : crs_wkt_of_epsg(c.epsg);
  const std::filesystem::path map_file = products::map_file_of(dir);
  std::vector<protocol::MapPoint> map = protocol::read_map(map_file);
  slam::Trajectory path = slam::read_tum(dir / "map_trajectory.tum");

  print_table(g, c, control.points.size());

  for (protocol::MapPoint& p : map) {
    const Eigen::Vector3d s = g.fit.apply(Eigen::Vector3d(p.x, p.y, p.z));
    p.x = s.x();
    p.y = s.y();
    p.z = s.z();
  }
  for (slam::Pose& pose : path.poses) pose = g.fit.apply(pose);

  const std::filesystem::path out = c.out.empty() ? dir / "georef" : std::filesystem::path(c.out);
  std::filesystem::create_directories(out);
  protocol::write_map(out / "map.las", protocol::MapFormat::las, map, {.crs_wkt = wkt, .ply_double = false});
  if (c.ply) protocol::write_map(out / "map.ply", protocol::MapFormat::ply, map, {.crs_wkt = {}, .ply_double = true});
  slam::write_tum(out / "map_trajectory.tum", path);
  {
    std::ofstream t(out / "targets.csv");
    t << "id,x,y,z\n";
    for (const eval::Target& target : targets) {
      const Eigen::Vector3d s = g.fit.apply(target.position);
      t << fmt::format("{},{:.4f},{:.4f},{:.4f}\n", target.id, s.x(), s.y(), s.z());
    }
    if (!t) throw InputError((out / "targets.csv").string(), "", "write failed");
  }
  std::ofstream json(out / "georef.json");
  json << to_json(g, c).dump(2) << "\n";
  if (!json) throw InputError((out / "georef.json").string(), "", "write failed");
  fmt::print("{} points, {} poses in site coordinates{} written to {}\n", map.size(), path.size(),
             c.epsg == 0 ? "" : fmt::format(" (EPSG:{})", c.epsg), out.string());
}

}  // namespace

void register_georef_commands(CLI::App& app, int& status) {
  auto* cmd = app.add_subcommand("georef", "Put a session's map and trajectory into site coordinates from control points");
  auto c = std::make_shared<GeorefCommand>();
  cmd->add_option("session", c->session, "The session folder (map.las, map_trajectory.tum)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--control", c->control, "Total-station CSV: id,E,N,H (header optional, names the column order)")->required();
  cmd->add_option("--targets", c->targets, "Targets found in the map: id,x,y,z[,sigma_m] (default SESSION/products/targets.csv)");
  cmd->add_flag("--scale", c->options.with_scale, "Fit a scale too (similarity), not only rotation and translation");
  cmd->add_flag("--level", c->options.level, "Turn the map about the vertical only (keeps the map's own tilt: aditd levels it by gravity); H by a shift");
  cmd->add_option("--tolerance", c->options.tolerance_m, "Flag residuals and check residuals above this (m, default 0.05)");
  cmd->add_option("--match", c->match, "How control points find their targets: auto (ids if they all match), id, geometry")
      ->check(CLI::IsMember({"auto", "id", "geometry"}));
  cmd->add_option("--match-tolerance", c->options.match_tolerance_m, "Pairwise distances agree within this + 0.2 % (m, default 0.25)");
  cmd->add_option("--units", c->units, "Units of the control file: m, ft (0.3048 m) or usft (1200/3937 m); default m");
  cmd->add_option("--epsg", c->epsg, "The site's CRS: written into the LAS file as OGC WKT (PROJ)");
  cmd->add_option("--out", c->out, "Where to write (default SESSION/georef)");
  cmd->add_flag("--ply", c->ply, "Also write map.ply (double coordinates)");
  cmd->callback([c, &status] {
    run_georef(*c);
    status = kExitOk;
  });
}

}  // namespace adit::tools
