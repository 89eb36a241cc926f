// What aditd's session listing says beside each id: recovered after a crash,
// joined to another session's map by `adit join`; nothing for a plain one or
// a join that failed or whose file is damaged.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "adit/daemon/products_worker.hpp"
#include "adit/daemon/sessions.hpp"
#include "adit/daemon/tile_store.hpp"
#include "adit/drivers/lidar/velodyne.hpp"
#include "adit/drivers/lidar/velodyne_encoder.hpp"
#include "plan_scene.hpp"
#include "plan_session.hpp"
#include "temp_file.hpp"

namespace adit::daemon {
namespace {

TEST(SessionNotes, RecoveredAndJoinedSessionsAreSaidSo) {
  const auto root = std::filesystem::temp_directory_path() / ("adit_session_notes_" + std::to_string(::getpid()));
  std::filesystem::remove_all(root);
  const auto plain = root / "A", recovered = root / "B", joined = root / "C", failed = root / "D", damaged = root / "E";
  for (const auto& d : {plain, recovered, joined, failed, damaged}) std::filesystem::create_directories(d);
  std::ofstream(plain / "summary.json") << R"({"map": {"points": 3}})";
  std::ofstream(recovered / "summary.json") << R"({"recovered": {"problem": ""}})";
  std::ofstream(joined / "summary.json") << R"({"map": {"points": 3}})";
  std::ofstream(joined / "joined.json") << R"({"joined_to": "A", "success": true})";
  std::ofstream(failed / "joined.json") << R"({"joined_to": "A", "success": false})";
  std::ofstream(damaged / "joined.json") << R"({"joined_to": )";
  EXPECT_EQ(session_notes(plain), "");
  EXPECT_EQ(session_notes(recovered), " recovered");
  EXPECT_EQ(session_notes(joined), " joined to A");
  EXPECT_EQ(session_notes(failed), "");
  EXPECT_EQ(session_notes(damaged), "");
  EXPECT_EQ(session_notes(root / "missing"), "");
  std::filesystem::remove_all(root);
}

// A stored session's tiles for a download: a session that mapped nothing
// (killed before its first map point) is an empty map; an unknown one is named.
TEST(StoredSessionTiles, ASessionThatMappedNothingIsAnEmptyMapAnUnknownOneIsNamed) {
  const test::TempFolder root;
  config::Config config;
  config.payload.state_dir = root.path().string();
  config.session.products = false;
  const test::TempFile calibration(
      drivers::format_velodyne_calibration(drivers::velodyne_nominal_calibration(drivers::VelodyneModel::vlp16)),
      ".yaml");
  config.lidar.model = "VLP-16";
  config.lidar.calibration = calibration.path().string();
  const auto empty = root.path() / "sessions" / "20261129T120000Z";
  std::filesystem::create_directories(empty);
  std::ofstream(empty / "summary.json") << R"({"map": {"points": 0}, "recovered": {"problem": ""}})";
  const Sessions sessions(config, {});
  TileStore tiles({});
  EXPECT_EQ(sessions.load_tiles("20261129T120000Z", tiles), "");
  EXPECT_EQ(tiles.tiles().size(), 0U);
  EXPECT_EQ(sessions.load_tiles("20261129T130000Z", tiles), "no stored tiles for session '20261129T130000Z'");
}

// aditd's worker with session.join_previous (and no products): the session
// is joined to the earlier one of the same floor, and the listing says so.
TEST(SessionNotes, TheWorkerJoinsASessionToTheEarlierOneItOverlaps) {
  using namespace slam::plan_scene;
  const test::TempFolder root;
  const std::vector<Eigen::Vector3f> world = sample_plan(two_halves(), 48, 16, 0.07, 0.01, 9);
  test::write_plan_session(root.path() / "20261128T080000Z", world, 25.0F, 3, 22, 0, level_frame(-3, 2, 0, 0.4));
  const auto session = root.path() / "20261128T100000Z";
  test::write_plan_session(session, world, 48.0F, 3, 45, 1000, level_frame(5, -7, 0, -2.2));
  AfterSessionSteps steps{false, true, {}};
  steps.join.place_spacing_m = 4.0;  // a small floor: places closer, clouds smaller than in a mine
  steps.join.cloud_radius_m = 12.0F;
  ProductsWorker worker(steps);
  worker.enqueue(session);
  worker.wait_idle();
  EXPECT_EQ(worker.joined(), 1U);
  EXPECT_EQ(worker.made(), 0U);  // products off
  EXPECT_EQ(session_notes(session), " joined to 20261128T080000Z");
}

}  // namespace
}  // namespace adit::daemon
