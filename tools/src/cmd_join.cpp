// adit join: a session's map placed into a stored session's map, so that a
// mine surveyed in several flights becomes one map (issue #20, part 5;
// docs/SESSIONS.md, Joining sessions). The stored map is prepared as a prior
// and places along the new session's path are localised in it
// (slam/session_join.hpp); two agreeing places, 10 m apart, make a join.
//
// Writes NEW/joined.json (the transform, the places, so `adit sessions` shows
// the join) and, with --out, a folder holding both maps and trajectories in
// the stored session's frame: map.ply and trajectory.tum, which can be joined
// to again (a third flight: `adit join S3 --to OUT --out OUT2`); the files are
// products/session_join_files.hpp's, which aditd uses too.

#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/common/error.hpp"
#include "adit/products/session_join_files.hpp"
#include "commands.hpp"
#include "eval_commands.hpp"

namespace adit::tools {
namespace {

struct JoinOptions {
  std::string session;
  std::string to;
  std::string out;
  std::vector<std::string> truth;  // the stored and the new session's truth_body.tum (simulated sessions)
  std::vector<double> shift;       // x y z yaw_deg: the session to join is moved by this before the search
  double place_spacing_m = 5.0;
  float radius_m = 20.0F;
  bool json = false;
};

int join(const JoinOptions& o) {
  const std::filesystem::path stored_dir(o.to), new_dir(o.session);
  products::JoinFilesOptions options;
  options.config.place_spacing_m = o.place_spacing_m;
  options.config.cloud_radius_m = o.radius_m;
  options.out = o.out;
  if (o.shift.size() == 4) {
    options.shift.linear() = Eigen::AngleAxisd(o.shift[3] * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    options.shift.translation() = Eigen::Vector3d(o.shift[0], o.shift[1], o.shift[2]);
  }
  const products::JoinFilesReport report = products::join_session_folders(new_dir, stored_dir, options);
  const slam::SessionJoinResult& r = report.result;
  nlohmann::json j = nlohmann::json::parse(report.json);
  if (o.truth.size() == 2) {
    // Simulated sessions: the join's error against the truth of both.
    std::size_t matched = 0;
    const Eigen::Isometry3d truth =
        world_from_map_fitted(o.truth[0], (stored_dir / "trajectory.tum").string(), matched).inverse() *
        world_from_map_fitted(o.truth[1], (new_dir / "trajectory.tum").string(), matched);
    const Eigen::Isometry3d e = r.stored_from_new.inverse() * truth;
    j["error"] = {{"translation_m", e.translation().norm()},
                  {"rotation_deg", Eigen::AngleAxisd(e.linear()).angle() * 180.0 / M_PI}};
  }
  if (o.json) {
    fmt::print("{}\n", j.dump(2));
    return r.success ? kExitOk : kExitFailure;
  }
  for (const slam::JoinPlace& p : r.places)
    fmt::print("  place at {:6.1f} m: {}{}\n", p.path_m,
               p.result.success ? fmt::format("localised, overlap {:.2f}", p.result.overlap) : p.result.failure,
               p.agrees ? " (agrees)" : "");
  if (!r.success) {
    fmt::print("not joined: {}\n", r.failure);
    return kExitFailure;
  }
  const Eigen::Vector3d t = r.stored_from_new.translation();
  const double yaw = std::atan2(r.stored_from_new.linear()(1, 0), r.stored_from_new.linear()(0, 0)) * 180.0 / M_PI;
  fmt::print("joined {} to {}: {} of {} places agree (from {:.0f} m of its path), overlap {:.2f}; "
             "translation ({:.3f}, {:.3f}, {:.3f}) m, yaw {:.2f} deg -> {}\n",
             products::folder_name(new_dir), report.stored_name, r.places_agreeing, r.places_tried,
             r.first_agreeing_path_m, r.overlap, t.x(), t.y(), t.z(), yaw, (new_dir / products::kJoinedFile).string());
  if (j.contains("error"))
    fmt::print("against the truth: {:.3f} m, {:.3f} deg\n", j["error"]["translation_m"].get<double>(),
               j["error"]["rotation_deg"].get<double>());
  if (!o.out.empty()) fmt::print("both sessions in {}'s frame: {}/map.ply, trajectory.tum\n", report.stored_name, o.out);
  return kExitOk;
}

}  // namespace

void register_join_commands(CLI::App& app, int& status) {
  auto o = std::make_shared<JoinOptions>();
  CLI::App* cmd = app.add_subcommand("join", "Place a session's map into a stored session's map (several flights, one map)");
  cmd->add_option("session", o->session, "The session to join (folder with map.ply, trajectory.tum)")->required();
  cmd->add_option("--to", o->to, "The stored session it continues (folder with map.ply, trajectory.tum)")->required();
  cmd->add_option("--out", o->out, "Write both, in the stored session's frame, to this folder (map.ply, trajectory.tum)");
  cmd->add_option("--place-spacing", o->place_spacing_m, "Try a place every this much of its path, m")
      ->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--radius", o->radius_m, "A place's cloud: its session's map within this distance, m")
      ->check(CLI::Range(5.0, 60.0))->capture_default_str();
  cmd->add_option("--truth", o->truth, "Simulated sessions: the stored and the new session's truth_body.tum (prints the join's error)")
      ->expected(2);
  cmd->add_option("--shift", o->shift,
                  "x y z yaw_deg: search with the session moved by this first (checks that nothing relies on the "
                  "sessions starting alike); the result is for the session as it is")
      ->expected(4);
  cmd->add_flag("--json", o->json, "Print the result as JSON");
  cmd->callback([o, &status] { status = join(*o); });
}

}  // namespace adit::tools
