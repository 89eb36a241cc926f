// adit eval moving: the moving objects `adit products` removed
// (moving_points.ply) and kept (map_static.*) against the simulator's people
// (truth_people.csv; eval/moving_truth.hpp).

#include <fmt/format.h>

#include "adit/eval/moving_truth.hpp"
#include "adit/protocol/map_import.hpp"
#include "eval_commands.hpp"

namespace adit::tools {
namespace {

std::vector<Eigen::Vector3d> world_points(const std::string& file, const Eigen::Isometry3d& world_from) {
  std::vector<Eigen::Vector3d> out;
  for (const protocol::MapPoint& p : protocol::read_map(file)) out.push_back(world_from * Eigen::Vector3d(p.x, p.y, p.z));
  return out;
}

}  // namespace

void run_eval_moving(const MovingEvalOptions& o) {
  const Eigen::Isometry3d world_from = world_from_map(o.ref, o.est);
  const std::vector<eval::PersonSample> people = eval::read_people_truth(o.people);
  const std::vector<Eigen::Vector3d> kept = world_points(o.kept, world_from);
  const std::vector<Eigen::Vector3d> removed = world_points(o.removed, world_from);
  eval::MovingLabels labels;
  labels.margin_m = o.margin;
  const eval::MovingScore s = eval::score_moving(kept, removed, people, labels);
  if (o.json) {
    fmt::print("{}\n", nlohmann::json{{"people_points", s.people_points},
                                      {"people_removed", s.people_removed},
                                      {"people_removed_fraction", s.people_removed_fraction()},
                                      {"static_points", s.static_points},
                                      {"static_removed", s.static_removed},
                                      {"static_removed_fraction", s.static_removed_fraction()}}
                           .dump(2));
    return;
  }
  fmt::print("people's points  {} in the map, {} removed ({:.2f} %)\n", s.people_points, s.people_removed,
             100.0 * s.people_removed_fraction());
  fmt::print("static points    {} in the map, {} removed ({:.3f} %)\n", s.static_points, s.static_removed,
             100.0 * s.static_removed_fraction());
}

}  // namespace adit::tools
