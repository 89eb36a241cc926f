// The session journal end to end without a pipeline: the writer's thread
// appends what the mapping thread hands it; a session cut short (no
// summary.json) is rebuilt from it, whatever tail a crash tore; a full disk
// stops the journal, not the caller.
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/daemon/journal_writer.hpp"
#include "adit/daemon/session_frame.hpp"
#include "adit/daemon/session_recovery.hpp"
#include "adit/slam/tum.hpp"
#include "map_readers.hpp"
#include "shared_data.hpp"

namespace adit::daemon {
namespace {

struct Written {
  std::size_t points = 0;
  std::size_t poses = 0;
  std::size_t keyframes = 0;
  std::set<slam::TileCoord> tiles;
};

// A session folder with a journal of `scans` scans (a pose, a few tiles' new
// points, a keyframe every 5th) written through JournalWriter, and a
// trajectory.tum that goes `extra_s` further (what the odometry saw after).
Written write_session(const std::filesystem::path& dir, int scans, double extra_s, std::uint32_t seed,
                      bool clean = false) {
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  Written w;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0F, 19.9F);
  const std::atomic<bool> stop{false};
  JournalWriter journal(dir / "journal.adj", 0.05, stop);
  journal.start(R"({"session":"s","tile_size_m":20.0,"voxel_m":0.05})");
  std::ofstream trajectory(dir / "trajectory.tum");
  for (int k = 0; k < scans; ++k) {
    const std::int64_t stamp = 1'700'000'000'000'000'000 + k * 100'000'000LL;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = Eigen::Vector3d(0.1 * k, 0.0, 0.0);
    journal.map_pose(stamp, pose);
    ++w.poses;
    trajectory << fmt::format("{:.9f} {} 0 0 0 0 0 1\n", 1e-9 * static_cast<double>(stamp), 0.1 * k);
    for (int t = 0; t < 3; ++t) {
      const slam::TileCoord c{k / 10 + t, t, 0};
      std::vector<slam::MapSample> points(20 + static_cast<std::size_t>(k % 7));
      for (slam::MapSample& p : points)
        p = {Eigen::Vector3f(20.0F * static_cast<float>(c.x) + u(rng), 20.0F * static_cast<float>(c.y) + u(rng), u(rng)),
             7.0F, 1e-9 * static_cast<double>(stamp)};
      journal.tile_points(c, points);
      w.points += points.size();
      w.tiles.insert(c);
    }
    if (k % 5 == 0) {
      const std::vector<Eigen::Vector3f> body(50, Eigen::Vector3f(1.0F, 2.0F, 3.0F));
      journal.keyframe(stamp, pose, body);
      ++w.keyframes;
    }
  }
  for (double t = 0.1; t <= extra_s + 1e-9; t += 0.1)
    trajectory << fmt::format("{:.9f} 0 0 0 0 0 0 1\n", 1.7e9 + 0.1 * (scans - 1) + t);
  journal.close(clean);  // cut short: no end record
  EXPECT_EQ(journal.fault(), "");
  EXPECT_EQ(journal.stats().lost_records.load(), 0U);
  return w;
}

std::filesystem::path work_dir(const std::string& name) {
  return test::binary_dir() / fmt::format("recovery-{}-{}", name, ::getpid()) / "sessions" / "20261126T000000Z";
}

TEST(SessionRecovery, AnInterruptedSessionIsFoundAndItsMapRebuiltWhole) {
  const std::filesystem::path dir = work_dir("whole");
  const Written w = write_session(dir, 40, 0.5, 1);
  ASSERT_EQ(interrupted_sessions(dir.parent_path()), std::vector<std::filesystem::path>{dir});

  const RecoveryReport r = recover_session(dir, {"ply", "las"}, 20.0);
  ASSERT_TRUE(r.recovered) << r.problem;
  EXPECT_EQ(r.points, w.points);
  EXPECT_EQ(r.tiles, w.tiles.size());
  EXPECT_EQ(r.map_poses, w.poses);
  EXPECT_EQ(r.keyframes, w.keyframes);
  EXPECT_EQ(r.cut_bytes, 0U);
  EXPECT_FALSE(r.ended_cleanly);
  EXPECT_NEAR(r.lost_s, 0.5, 1e-6);  // the odometry's trajectory went 0.5 s further
  EXPECT_EQ(test::read_ply(dir / "map.ply").size(), w.points);
  EXPECT_TRUE(std::filesystem::exists(dir / "map.las"));
  std::size_t tile_files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir / "tiles")) tile_files += e.path().extension() == ".adt";
  EXPECT_EQ(tile_files, w.tiles.size());
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(dir / "summary.json"));
  EXPECT_EQ(summary["recovered"]["map_poses"], w.poses);
  EXPECT_EQ(summary["map"]["points"], w.points);
  EXPECT_FALSE(std::filesystem::exists(dir / "journal.adj"));  // its content is in the files now
  EXPECT_TRUE(interrupted_sessions(dir.parent_path()).empty());
  EXPECT_NE(describe(r).find("recovered"), std::string::npos);
}

// A journal closed cleanly (the crash came while the files were written)
// ends with its end record, and holds each point once.
TEST(SessionRecovery, ACleanlyClosedJournalEndsWithItsEndRecordAndEachPointOnce) {
  const std::filesystem::path dir = work_dir("clean");
  const Written w = write_session(dir, 25, 0.0, 4, true);
  const RecoveryReport r = recover_session(dir, {"ply"}, 20.0);
  ASSERT_TRUE(r.recovered) << r.problem;
  EXPECT_TRUE(r.ended_cleanly);
  EXPECT_EQ(r.cut_bytes, 0U);
  EXPECT_EQ(r.points, w.points);
  EXPECT_EQ(r.map_poses, w.poses);
}

// A crash while the session's end wrote the graph's tiles (tiles_graph/, or
// its .partial): the recovered map does not follow the graph, so a download
// must not be served from them; they go, and the frame is the odometry's.
TEST(SessionRecovery, TheGraphsTilesOfAnEndCutShortGo) {
  const std::filesystem::path dir = work_dir("graph-tiles");
  write_session(dir, 25, 0.0, 5, true);
  for (const char* folder : {"tiles_graph", "tiles_graph.partial"}) {
    std::filesystem::create_directories(dir / folder);
    std::ofstream(dir / folder / "0.adt") << "half a tile";
  }
  write_graph_correction(dir / kGraphTilesFolder / kGraphCorrectionFile, Eigen::Isometry3d::Identity());
  ASSERT_TRUE(stored_session_frame(dir).has_value());
  const RecoveryReport r = recover_session(dir, {"ply"}, 20.0);
  ASSERT_TRUE(r.recovered) << r.problem;
  EXPECT_FALSE(std::filesystem::exists(dir / "tiles_graph"));
  EXPECT_FALSE(std::filesystem::exists(dir / "tiles_graph.partial"));
  EXPECT_TRUE(std::filesystem::is_directory(dir / "tiles"));
  EXPECT_FALSE(stored_session_frame(dir).has_value());
}

// Wherever the crash cut the journal, what came before the cut is recovered
// and the rest is named as lost; the file itself is cut back to whole records.
TEST(SessionRecovery, ATornJournalIsCutAtItsLastGoodRecordAndTheRestRecovered) {
  const std::filesystem::path reference_dir = work_dir("torn-ref");
  const Written w = write_session(reference_dir, 30, 0.0, 2);
  const std::uintmax_t size = std::filesystem::file_size(reference_dir / "journal.adj");
  std::mt19937 rng(11);
  std::size_t previous_points = 0;
  std::vector<std::uintmax_t> cuts;
  for (int i = 0; i < 12; ++i) cuts.push_back(std::uniform_int_distribution<std::uintmax_t>(100, size - 1)(rng));
  std::sort(cuts.begin(), cuts.end());
  for (const std::uintmax_t cut : cuts) {
    const std::filesystem::path dir = work_dir("torn");
    write_session(dir, 30, 0.0, 2);
    std::filesystem::resize_file(dir / "journal.adj", cut);
    const RecoveryReport r = recover_session(dir, {"ply"}, 20.0);
    ASSERT_TRUE(r.recovered) << r.problem;
    EXPECT_LE(r.points, w.points);
    EXPECT_GE(r.points, previous_points);  // a later cut never loses more
    previous_points = r.points;
    EXPECT_EQ(test::read_ply(dir / "map.ply").size(), r.points);
    if (r.cut_bytes > 0) {
      EXPECT_NE(r.cut_reason, "") << cut;
    }
    EXPECT_GT(r.lost_s, 0.0) << "cut at " << cut << " of " << size;  // the trajectory went further
  }
}

TEST(SessionRecovery, AFullDiskStopsTheJournalAndNamesItWithoutStoppingTheCaller) {
  const std::atomic<bool> stop{false};
  JournalWriter journal("/dev/full", 0.05, stop);  // every write: ENOSPC
  journal.start(R"({"session":"full"})");
  for (int k = 0; k < 100; ++k) journal.map_pose(k, Eigen::Isometry3d::Identity());
  journal.close(true);
  EXPECT_NE(journal.fault().find("No space left"), std::string::npos) << journal.fault();
  EXPECT_EQ(journal.stats().lost_records.load(), 100U);
  EXPECT_EQ(journal.stats().records.load(), 0U);
}

TEST(SessionRecovery, AJournalThatCannotBeCreatedIsNamed) {
  const std::atomic<bool> stop{false};
  JournalWriter journal("/nonexistent-folder/journal.adj", 0.5, stop);
  try {
    journal.start("{}");
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-folder/journal.adj"), std::string::npos) << e.what();
  }
}

// A recovery that itself crashed is not tried again on every start (a crash loop).
TEST(SessionRecovery, ARecoveryThatCrashedIsNotTriedAgain) {
  const std::filesystem::path dir = work_dir("attempt");
  write_session(dir, 5, 0.0, 3);
  std::ofstream(dir / "recovery.attempt") << "recovering\n";
  const RecoveryReport r = recover_session(dir, {"ply"}, 20.0);
  EXPECT_FALSE(r.recovered);
  EXPECT_NE(r.problem.find("did not finish"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir / "journal.adj"));  // kept for a person to look at
  EXPECT_TRUE(interrupted_sessions(dir.parent_path()).empty());  // summary.json says why
}

// A session anchored to a prior map before the crash (its prior_frame.json)
// is recovered in the prior's frame, as it would have ended: the map files and
// the trajectories moved by the anchor, tiles/ left in the odometry frame.
TEST(SessionRecovery, AnAnchoredSessionIsRecoveredInThePriorsFrame) {
  const std::filesystem::path plain = work_dir("plain");
  const std::filesystem::path anchored = work_dir("anchored");
  write_session(plain, 20, 0.0, 4);
  write_session(anchored, 20, 0.0, 4);
  Eigen::Isometry3d anchor = Eigen::Isometry3d::Identity();
  anchor.linear() = Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  anchor.translation() = Eigen::Vector3d(-130.0, 45.5, 2.25);  // below every odometry point: the LAS corner must follow
  write_prior_frame(anchored / "prior_frame.json", anchor);
  ASSERT_TRUE(recover_session(plain, {"ply", "las"}, 20.0).recovered);
  const RecoveryReport r = recover_session(anchored, {"ply", "las"}, 20.0);
  ASSERT_TRUE(r.recovered) << r.problem;
  ASSERT_EQ(r.frame.source, ExportSource::prior_map);

  const std::vector<test::XyzI> before = test::read_ply(plain / "map.ply");
  const std::vector<test::XyzI> after = test::read_ply(anchored / "map.ply");
  ASSERT_EQ(before.size(), after.size());
  for (std::size_t i = 0; i < before.size(); ++i) {
    const Eigen::Vector3d expected = anchor * Eigen::Vector3d(before[i].x, before[i].y, before[i].z);
    ASSERT_LT((Eigen::Vector3d(after[i].x, after[i].y, after[i].z) - expected).norm(), 1e-3) << i;
  }
  for (const char* file : {"trajectory.tum", "map_trajectory.tum", "keyframes.tum"}) {
    const slam::Trajectory a = slam::read_tum(plain / file);
    const slam::Trajectory b = slam::read_tum(anchored / file);
    ASSERT_EQ(a.size(), b.size()) << file;
    for (std::size_t i = 0; i < a.size(); ++i)
      ASSERT_TRUE((anchor * a.poses[i]).isApprox(b.poses[i], 1e-6)) << file << " pose " << i;
  }
  for (const auto& e : std::filesystem::directory_iterator(plain / "tiles"))  // the odometry frame's, byte for byte
    EXPECT_EQ(test::slurp(e.path()), test::slurp(anchored / "tiles" / e.path().filename())) << e.path();
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(anchored / "summary.json"));
  EXPECT_EQ(summary["frame"]["name"], "prior_map");
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(plain / "summary.json"))["frame"]["name"], "odometry");
}

TEST(SessionRecovery, ABrokenPriorFrameLeavesTheSessionInTheOdometryFrame) {
  const std::filesystem::path dir = work_dir("broken-frame");
  write_session(dir, 5, 0.0, 5);
  std::ofstream(dir / "prior_frame.json") << R"({"prior_from_odometry": [[1, 0, 0], [0, 1, 0]]})";
  const RecoveryReport r = recover_session(dir, {"ply"}, 20.0);
  ASSERT_TRUE(r.recovered) << r.problem;  // nothing is lost for a bad anchor
  EXPECT_EQ(r.frame.source, ExportSource::odometry);
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(dir / "summary.json"))["frame"]["name"], "odometry");
}

}  // namespace
}  // namespace adit::daemon
