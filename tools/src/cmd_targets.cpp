// adit targets find SESSION_DIR --out FILE.csv: retro-reflective targets found
// in a session's map (products/target_finder.hpp), as id,x,y,z,sigma_m in the
// map frame (docs/PRODUCTS.md).

#include <memory>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/products/session_map.hpp"
#include "adit/products/target_finder.hpp"
#include "adit/protocol/map_import.hpp"
#include "adit/slam/tum.hpp"
#include "commands.hpp"

namespace adit::tools {
namespace {

struct TargetsCommand {
  std::string session, out;
  products::TargetOptions options;
};

void run_targets_find(const TargetsCommand& c) {
  const std::filesystem::path dir = c.session;
  const std::filesystem::path map_file = products::map_file_of(dir);
  const std::vector<protocol::MapPoint> map = protocol::read_map(map_file);
  const slam::Trajectory path = slam::read_tum(dir / "map_trajectory.tum");
  std::vector<Eigen::Vector3f> points;
  std::vector<float> intensities;
  float brightest = 0.0F;
  for (const protocol::MapPoint& p : map) {
    points.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z));
    intensities.push_back(p.intensity);
    brightest = std::max(brightest, p.intensity);
  }
  if (brightest <= 0.0F)
    throw InputError(map_file.string(), "intensity", "the map has no intensities: targets cannot be found");
  const std::vector<products::FoundTarget> found = products::find_targets(points, intensities, path, c.options);
  products::write_targets_csv(c.out, found);
  fmt::print("{} targets in {} (intensity >= {}), written to {}\n", found.size(), map_file.string(),
             c.options.min_intensity, c.out);
}

}  // namespace

void register_targets_commands(CLI::App& app, int& status) {
  auto* targets = app.add_subcommand("targets", "Survey targets in a session's map");
  targets->require_subcommand(1);
  auto* find = targets->add_subcommand("find", "Find retro-reflective targets: id,x,y,z,sigma_m in the map frame");
  auto c = std::make_shared<TargetsCommand>();
  find->add_option("session", c->session, "The session folder (map.las, map_trajectory.tum)")
      ->required()
      ->check(CLI::ExistingDirectory);
  find->add_option("--out", c->out, "CSV file to write")->required();
  find->add_option("--min-intensity", c->options.min_intensity, "Brightness of a target's points (default 150)");
  find->add_option("--max-path-distance", c->options.max_path_distance_m, "Farther from the path is not looked at (m, default 30)");
  find->callback([c, &status] {
    run_targets_find(*c);
    status = kExitOk;
  });
}

}  // namespace adit::tools
