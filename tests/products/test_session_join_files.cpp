// Joining session folders: after a session, the earlier sessions are tried
// newest first; one of another building is refused and the next, of the same
// floor, joined (joined.json names it); unreadable files are named.
#include <gtest/gtest.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "adit/common/error.hpp"
#include "adit/products/session_join_files.hpp"
#include "plan_scene.hpp"
#include "plan_session.hpp"
#include "temp_file.hpp"

namespace adit::products {
namespace {

using namespace slam::plan_scene;

JoinFilesOptions quick() {
  JoinFilesOptions o;
  o.config.place_spacing_m = 4.0;
  o.config.cloud_radius_m = 12.0F;
  o.config.localisation.max_search_points = 300;
  return o;
}

TEST(SessionJoinFiles, TheNewestEarlierSessionItOverlapsIsJoined) {
  const test::TempFolder root;
  const std::vector<Eigen::Vector3f> world = sample_plan(two_halves(), 48, 16, 0.07, 0.01, 9);
  test::write_plan_session(root.path() / "20261128T080000Z", world, 25.0F, 3, 22, 0, level_frame(-3, 2, 0, 0.4));
  test::write_plan_session(root.path() / "20261128T090000Z", sample_plan(other_building(), 30, 20, 0.07, 0.01, 5), 30.0F,
                           3, 27, 100, level_frame(1, 1, 0, 1.0));
  std::filesystem::create_directories(root.path() / "20261128T093000Z");  // no map: not tried
  const auto session = root.path() / "20261128T100000Z";
  test::write_plan_session(session, world, 48.0F, 3, 45, 1000, level_frame(5, -7, 0, -2.2));
  test::write_plan_session(root.path() / "20261128T110000Z", world, 48.0F, 3, 45, 2000, Eigen::Isometry3d::Identity());  // later: not tried

  const std::vector<JoinFilesReport> reports = join_previous_session(session, 3, quick());
  ASSERT_EQ(reports.size(), 2U);
  EXPECT_EQ(reports[0].stored_name, "20261128T090000Z");
  EXPECT_FALSE(reports[0].result.success);
  EXPECT_EQ(reports[1].stored_name, "20261128T080000Z");
  ASSERT_TRUE(reports[1].result.success) << reports[1].result.failure;
  std::ifstream in(session / kJoinedFile);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["joined_to"], "20261128T080000Z");
  EXPECT_EQ(j["places"].size(), static_cast<std::size_t>(reports[1].result.places_tried));
}

TEST(SessionJoinFiles, AMissingOrEmptyFileIsNamed) {
  const test::TempFolder root;
  std::filesystem::create_directories(root.path() / "A");
  std::filesystem::create_directories(root.path() / "B");
  std::ofstream(root.path() / "A" / "trajectory.tum") << "";
  try {
    join_session_folders(root.path() / "B", root.path() / "A");
    FAIL() << "joined without files";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("map.ply"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace adit::products
