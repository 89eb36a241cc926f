// End-to-end: `adit join` on two hand-made session folders (map.ply,
// trajectory.tum) of one floor in frames of their own: the second is placed
// in the first's frame, joined.json says so, --out holds both; a missing map
// exits 2 naming it.

#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "adit/protocol/map_import.hpp"
#include "adit/slam/tum.hpp"
#include "plan_scene.hpp"
#include "plan_session.hpp"
#include "run_adit.hpp"
#include "temp_file.hpp"

namespace adit {
namespace {

using namespace slam::plan_scene;
using test::adit_command;
using test::TempFolder;

TEST(AditJoin, ASecondSessionIsPlacedInTheFirstsFrameAndBothAreWritten) {
  const TempFolder root;
  const std::vector<Eigen::Vector3f> world = sample_plan(two_halves(), 48, 16, 0.07, 0.01, 9);
  const Eigen::Isometry3d stored_from_world = level_frame(-3.0, 2.0, 0.0, 0.4),
                          new_from_world = level_frame(5.0, -7.0, 0.0, -2.2);
  const std::size_t stored_points = test::write_plan_session(root.path() / "S", world, 25.0F, 3, 22, 0, stored_from_world);
  const std::size_t new_points = test::write_plan_session(root.path() / "N", world, 48.0F, 3, 45, 1000, new_from_world);
  const auto run = adit_command("join '" + (root.path() / "N").string() + "' --to '" + (root.path() / "S").string() +
                                "/' --radius 12 --place-spacing 4 --out '" + (root.path() / "both").string() + "' 2>&1");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("joined N to S"), std::string::npos) << run.output;

  std::ifstream in(root.path() / "N" / "joined.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["joined_to"], "S");
  EXPECT_TRUE(j["success"].get<bool>());
  const auto& t = j["stored_from_new"];
  Eigen::Isometry3d found = Eigen::Isometry3d::Identity();
  found.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  found.linear() = Eigen::Quaterniond(t[6].get<double>(), t[3], t[4], t[5]).normalized().toRotationMatrix();
  const Eigen::Isometry3d e = found.inverse() * stored_from_world * new_from_world.inverse();
  EXPECT_LT(e.translation().norm(), 0.03);
  EXPECT_LT(Eigen::AngleAxisd(e.linear()).angle(), 0.005);

  EXPECT_EQ(protocol::read_map(root.path() / "both" / "map.ply").size(), stored_points + new_points);
  const slam::Trajectory both = slam::read_tum(root.path() / "both" / "trajectory.tum");
  ASSERT_EQ(both.size(), 39U + 85U);
  // The new session's last pose (x = 45 in the world) lands where the world puts it in the stored frame.
  EXPECT_LT((both.poses.back().translation() - stored_from_world * Eigen::Vector3d(45, 11.5, 0.2)).norm(), 0.05);
}

TEST(AditJoin, AMissingMapIsNamed) {
  const TempFolder root;
  const auto run = adit_command("join '" + (root.path() / "N").string() + "' --to '" + root.path().string() + "' 2>&1");
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("map.ply"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace adit
