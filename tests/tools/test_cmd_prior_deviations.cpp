// End-to-end: `adit prior-map deviations` on a hand-made session folder
// (map.ply, trajectory.tum) of a floor whose built partition stands 0.3 m from
// where the design (the prior) draws it. Placed in the prior by its own
// localisation or given --aligned, the moved wall is the largest region;
// against the built scene (--truth-scene) the deviating points are scored and
// each point's label is written beside its deviation; an empty map exits 2
// naming the session.

#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "adit/protocol/map_export.hpp"
#include "plan_scene.hpp"
#include "plan_session.hpp"
#include "run_adit.hpp"
#include "temp_file.hpp"

namespace adit {
namespace {

using namespace slam::plan_scene;
using test::adit_command;
using test::TempFolder;

void write_points(const std::filesystem::path& file, const std::vector<Eigen::Vector3f>& points) {
  std::vector<protocol::MapPoint> out;
  for (const auto& p : points) out.push_back({p.x(), p.y(), p.z(), 10.0F, 0.0});
  protocol::write_map(file, protocol::MapFormat::ply, out);
}

struct Floor {
  TempFolder root;
  std::filesystem::path session = root.path() / "S";
  std::filesystem::path prior = root.path() / "design.ply";
  std::filesystem::path scene = root.path() / "built.ply";

  // The map in the session's own frame (identity: already in the prior's).
  explicit Floor(const Eigen::Isometry3d& session_from_world) {
    write_points(prior, sample_plan(office(), 24, 16, 0.1));
    write_points(scene, sample_plan(office(0.3), 24, 16, 0.05));
    test::write_plan_session(session, sample_plan(office(0.3), 24, 16, 0.07, 0.01, 5), 24.0F, 3, 22, 0,
                             session_from_world);
  }

  nlohmann::json run(const std::string& more) const {
    const auto r = adit_command("prior-map deviations '" + session.string() + "' --prior '" + prior.string() + "' --out '" +
                                (root.path() / "dev").string() + "' --truth-scene '" + scene.string() + "' --json " +
                                more + " 2>&1");
    EXPECT_EQ(r.status, 0) << r.output;
    return nlohmann::json::parse(r.output.substr(r.output.find('{')));
  }
};

void expect_the_moved_wall(const nlohmann::json& j) {
  ASSERT_FALSE(j["regions"].empty()) << j.dump(1);
  const auto& wall = j["regions"][0];  // the largest
  EXPECT_NEAR(wall["centroid_m"][0].get<double>(), 8.15, 0.4) << wall.dump();
  EXPECT_GT(wall["size_m"][1].get<double>(), 9.0) << wall.dump();
  EXPECT_GT(wall["mean_deviation_m"].get<double>(), 0.2) << wall.dump();  // towards the path at y = 11.5, x > 8
  // The scene's only real difference is that wall (and the floor and ceiling strip it left).
  const auto& t = j["truth"];
  EXPECT_GT(t["changed_points"].get<double>(), 1000.0) << t.dump();
  EXPECT_GT(t["precision_points"].get<double>(), 0.9) << t.dump();
  EXPECT_GT(t["recall_points"].get<double>(), 0.9) << t.dump();
}

TEST(AditPriorDeviations, AMapAlreadyInThePriorsFrameShowsTheMovedWallAndItsLabels) {
  const Floor floor(Eigen::Isometry3d::Identity());
  const nlohmann::json j = floor.run("--aligned");
  expect_the_moved_wall(j);
  // deviations.ply: the deviation, its region and the truth's label for each map point.
  std::ifstream ply(floor.root.path() / "dev" / "deviations.ply", std::ios::binary);
  std::string header, line;
  while (std::getline(ply, line) && line != "end_header") header += line + "\n";
  for (const char* field : {"property float deviation", "property float region", "property float truth"})
    EXPECT_NE(header.find(field), std::string::npos) << header;
}

TEST(AditPriorDeviations, AMapInItsOwnFrameIsPlacedByLocalisationFirst) {
  const Floor floor(level_frame(-3.0, 2.0, 0.0, 0.4));
  expect_the_moved_wall(floor.run(""));
}

TEST(AditPriorDeviations, AnEmptyMapIsNamed) {
  const Floor floor(Eigen::Isometry3d::Identity());
  write_points(floor.session / "map.ply", {});
  const auto r = adit_command("prior-map deviations '" + floor.session.string() + "' --prior '" + floor.prior.string() +
                              "' --out '" + (floor.root.path() / "dev").string() + "' 2>&1");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(floor.session.string()), std::string::npos) << r.output;
}

}  // namespace
}  // namespace adit
