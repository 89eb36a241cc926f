// A session whose path leaves tiles behind: the mapping thread evicts them to
// the session's tiles/ folder during the session and reloads them when it
// comes back, and still the stop-time exports, the stored tiles (what a
// download serves) and the tiles published live hold every map point; against
// a session that kept every tile in RAM only unconfirmed voxels are lost.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <chrono>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "adit/config/load.hpp"
#include "adit/daemon/session_recovery.hpp"
#include "adit/daemon/sessions.hpp"
#include "adit/daemon/tile_store.hpp"
#include "adit/protocol/tile_codec.hpp"
#include "daemon_process.hpp"
#include "map_readers.hpp"
#include "point_match.hpp"
#include "run_program.hpp"
#include "shared_data.hpp"

namespace adit::daemon {
namespace {

using namespace std::chrono_literals;

// 21 s of a robot in a mine drift (seed 1): a second still, 6 m down the
// drift at 1 m/s, a stop, a turn and back; generated once per build tree.
std::filesystem::path driving_session() {
  const std::filesystem::path dir = test::binary_dir() / "evict-session-21s";
  if (!std::filesystem::exists(dir / "lidar.pcap")) {
    const test::CommandRun sim = test::run_adit(fmt::format(
        "sim --scene mine --platform robot --sensor VLP-16 --duration 21 --seed 1 --out {}", dir.string()));
    EXPECT_EQ(sim.status, 0) << sim.output;
  }
  return dir;
}

struct SessionRun {
  std::filesystem::path folder;
  nlohmann::json summary;
  std::map<std::int64_t, std::size_t> published;  // tile id → points in its newest live update
  std::size_t updates = 0;       // tile updates published
  std::size_t tail_updates = 0;  // ... of them, those that carried only what the tile gained
  std::size_t out_of_step = 0;   // updates starting beyond what the tile held
};

// Small tiles (5 m) and a short mapping range (5 m, margin 1 m) so that the
// drive leaves tiles behind (evict_after_keyframes 0: every tile stays in RAM);
// compact_tile_voxels 0: never compacted; resident_tiles_mb 0: no budget.
SessionRun map_session(const std::filesystem::path& work, int evict_after_keyframes, int compact_tile_voxels,
                       double keyframe_distance_m = 1.0, double keyframe_angle_deg = 10.0,
                       double resident_tiles_mb = 0.0) {
  const std::filesystem::path session = driving_session();
  // As fast as possible: a replay waits, nothing is dropped. The journal is
  // kept, so that the map can be rebuilt from it too (expect_every_point_everywhere).
  const std::string yaml = test::aditd_yaml_for(
      session, work / "state",
      {"", "", true,
       fmt::format("map:\n  tile_size_m: 5\n  max_range_m: 5\n  evict_margin_m: 1\n  evict_after_keyframes: {}\n"
                   "  compact_tile_voxels: {}\n  keyframe_distance_m: {}\n  keyframe_angle_deg: {}\n"
                   "  resident_tiles_mb: {}\n"
                   "session:\n  exports: [ply, las]\n  keep_journal: true\nthreads:\n  lock_memory: false\n",
                   evict_after_keyframes, compact_tile_voxels, keyframe_distance_m, keyframe_angle_deg,
                   resident_tiles_mb)});
  std::filesystem::create_directories(work);
  const std::filesystem::path config_file = work / "aditd.yaml";
  std::ofstream(config_file) << yaml;

  SessionRun run;
  std::mutex mutex;
  Sessions::Outputs outputs;
  outputs.tile = [&](TileUpdate&& update) {
    const std::lock_guard lock(mutex);
    std::size_t& held = run.published[protocol::tile_id(update.key)];
    ++run.updates;
    if (update.first_point > 0) ++run.tail_updates;
    if (update.first_point > held) ++run.out_of_step;
    held = update.first_point + update.points.size();
    return true;
  };
  Sessions sessions(config::load_config(config_file), outputs);
  const std::string id = sessions.start();
  const auto deadline = std::chrono::steady_clock::now() + 300s;
  while (!sessions.poll() && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(20ms);
  sessions.stop_and_wait();
  run.folder = sessions.folder(id);
  run.summary = nlohmann::json::parse(std::ifstream(run.folder / "summary.json"));
  return run;
}

// Every point of the session's map is in its exports, in its tiles/ (what a
// download serves) and, per tile, in the newest update published live.
void expect_every_point_everywhere(const SessionRun& run, const std::filesystem::path& config_file) {
  const nlohmann::json& map = run.summary["map"];
  const std::size_t points = map["points"];
  EXPECT_EQ(map["tile_file_errors"], 0);
  EXPECT_EQ(map["dropped_in_evicted"], 0);
  EXPECT_EQ(test::read_ply(run.folder / "map.ply").size(), points);
  EXPECT_EQ(test::read_las_checked(run.folder / "map.las").size(), points);

  TileStore stored({5.0, 0.001, 3});
  Sessions reader(config::load_config(config_file), {});
  ASSERT_EQ(reader.load_tiles(run.folder.filename().string(), stored), "");
  EXPECT_EQ(stored.total_points(), static_cast<std::int64_t>(points));
  EXPECT_EQ(stored.tiles().size(), map["tiles"].get<std::size_t>());

  // Tiles whose voxels never reached min_hits are stored empty and never published.
  std::size_t non_empty = 0;
  for (const auto& [id, tile] : stored.tiles()) {
    if (tile.n_points == 0) continue;
    ++non_empty;
    const auto it = run.published.find(id);
    ASSERT_NE(it, run.published.end()) << "tile " << id << " was never published";
    EXPECT_EQ(it->second, static_cast<std::size_t>(tile.n_points)) << "tile " << id;
  }
  EXPECT_EQ(run.published.size(), non_empty);
  // A tile's updates carry what it gained (decision 074), through evictions,
  // reloads and compactions, each from the point the tile held.
  // Without a correction to re-place them, every update after a tile's first
  // is what it gained.
  EXPECT_EQ(run.out_of_step, 0U);
  EXPECT_GT(run.tail_updates, 0U);
  if (run.summary["loops"].value("optimizations", 0) == 0) {
    EXPECT_EQ(run.tail_updates, run.updates - run.published.size()) << run.updates << " updates";
  }

  // The session's journal holds the same map through every eviction, reload
  // and compaction: rebuilt from it alone, as after a crash, it has every point
  // (levelled as the session's end did, by the level_frame.json a crash leaves too).
  const std::filesystem::path copy = run.folder.parent_path().parent_path() / "recovered" / run.folder.filename();
  std::filesystem::remove_all(copy);
  std::filesystem::create_directories(copy);
  std::filesystem::copy_file(run.folder / "journal.adj", copy / "journal.adj");
  if (std::filesystem::exists(run.folder / "level_frame.json"))
    std::filesystem::copy_file(run.folder / "level_frame.json", copy / "level_frame.json");
  const RecoveryReport recovery = recover_session(copy, {"ply"}, 20.0);
  ASSERT_TRUE(recovery.recovered) << recovery.problem;
  EXPECT_TRUE(recovery.ended_cleanly);
  EXPECT_EQ(recovery.points, points);
  EXPECT_EQ(recovery.tiles, map["tiles"].get<std::size_t>());
  const std::vector<test::XyzI> original = test::read_ply(run.folder / "map.ply");
  const std::vector<test::XyzI> rebuilt = test::read_ply(copy / "map.ply");
  EXPECT_EQ(test::unmatched(rebuilt, original, 0.0006), 0U);  // the tile files keep 1 mm
  EXPECT_EQ(test::unmatched(original, rebuilt, 0.0006), 0U);
}

struct Comparison {
  std::size_t kept_missing = 0;  // points of the all-in-RAM map not in the other
  std::size_t new_points = 0;    // points of the other map not in the all-in-RAM one
};

// Map points matched within the tile codec's quantum (1 mm: half of it per axis, plus float rounding).
Comparison compare_maps(const SessionRun& kept, const SessionRun& other) {
  const std::vector<test::XyzI> a = test::read_ply(kept.folder / "map.ply");
  const std::vector<test::XyzI> b = test::read_ply(other.folder / "map.ply");
  const Comparison c{test::unmatched(a, b, 0.0006), test::unmatched(b, a, 0.0006)};
  const nlohmann::json& map = other.summary["map"];
  fmt::print("{} map points ({} with every tile in RAM); {} evictions, {} reloads, {} compactions, {} unconfirmed "
             "voxels lost; {} points of the all-in-RAM map missing, {} points not in it\n",
             map["points"].get<std::size_t>(), a.size(), map["evicted_tiles"].get<std::size_t>(),
             map["restored_tiles"].get<std::size_t>(), map["compacted_tiles"].get<std::size_t>(),
             map["lost_candidates"].get<std::size_t>(), c.kept_missing, c.new_points);
  return c;
}

class SessionEviction : public testing::Test {
 protected:
  void SetUp() override { std::filesystem::remove_all(work); }
  void TearDown() override { std::filesystem::remove_all(work); }
  const std::filesystem::path work = test::binary_dir() / fmt::format("session-eviction-{}", ::getpid());
};

TEST_F(SessionEviction, TilesLeftBehindAreEvictedAndReloadedAndTheMapStillHoldsEveryPoint) {
  const SessionRun kept = map_session(work / "kept", 0, 0);
  const SessionRun evicting = map_session(work / "evicting", 3, 0);
  const nlohmann::json& map = evicting.summary["map"];
  ASSERT_GT(map["points"].get<std::size_t>(), 10'000U);
  // The drive goes 6 m down the drift, turns and comes back: tiles are left and re-entered.
  EXPECT_GT(map["evicted_tiles"].get<std::size_t>(), 3U) << map.dump();
  EXPECT_GT(map["restored_tiles"].get<std::size_t>(), 0U) << map.dump();
  EXPECT_EQ(kept.summary["map"]["evicted_tiles"], 0);
  EXPECT_EQ(map["tiles"], kept.summary["map"]["tiles"]);  // re-entered tiles were continued, not duplicated
  expect_every_point_everywhere(evicting, work / "evicting" / "aditd.yaml");

  // Against the session that kept every tile in RAM, eviction costs only the
  // voxels hit fewer than min_hits times before their tile left (lost candidates).
  const Comparison c = compare_maps(kept, evicting);
  const std::size_t lost = map["lost_candidates"];
  const std::size_t kept_points = kept.summary["map"]["points"];
  EXPECT_LE(c.kept_missing, lost);
  EXPECT_LE(c.new_points, lost);
  EXPECT_LT(c.kept_missing, kept_points / 50);
  EXPECT_LT(c.new_points, kept_points / 50);
}

TEST_F(SessionEviction, CrowdedTilesAreCompactedAndTheMapStillHoldsEveryPoint) {
  const SessionRun kept = map_session(work / "kept", 0, 0);
  // A tile is compacted each time it holds 3000 voxels in RAM: many times in 21 s.
  const SessionRun compacting = map_session(work / "compacting", 3, 3000);
  const nlohmann::json& map = compacting.summary["map"];
  EXPECT_GT(map["compacted_tiles"].get<std::size_t>(), 5U) << map.dump();
  EXPECT_EQ(kept.summary["map"]["compacted_tiles"], 0);
  EXPECT_EQ(map["tiles"], kept.summary["map"]["tiles"]);
  expect_every_point_everywhere(compacting, work / "compacting" / "aditd.yaml");
  // Each compaction drops the tile's unconfirmed voxels: what differs is bounded by them.
  const Comparison c = compare_maps(kept, compacting);
  EXPECT_LE(c.kept_missing, map["lost_candidates"].get<std::size_t>());
  EXPECT_LE(c.new_points, map["lost_candidates"].get<std::size_t>());
}

TEST_F(SessionEviction, OverTheBudgetTheLargestTilesAreCompactedAndTheMapStillHoldsEveryPoint) {
  const SessionRun kept = map_session(work / "kept", 0, 0);
  const SessionRun unbounded = map_session(work / "unbounded", 3, 0);
  const double peak_mb = unbounded.summary["map"]["peak_resident_tiles_mb"];
  ASSERT_GT(peak_mb, 0.0);
  EXPECT_EQ(unbounded.summary["map"]["compacted_tiles"], 0);
  // Half of what the tiles held at most: compacted in rounds, never far over it.
  const double budget_mb = peak_mb / 2;
  const SessionRun bounded = map_session(work / "bounded", 3, 0, 1.0, 10.0, budget_mb);
  const nlohmann::json& map = bounded.summary["map"];
  EXPECT_GT(map["compacted_tiles"].get<std::size_t>(), 0U) << map.dump();
  EXPECT_LT(map["peak_resident_tiles_mb"].get<double>(), 0.75 * peak_mb) << map.dump();
  EXPECT_EQ(map["tiles"], kept.summary["map"]["tiles"]);
  expect_every_point_everywhere(bounded, work / "bounded" / "aditd.yaml");
  const Comparison c = compare_maps(kept, bounded);
  EXPECT_LE(c.kept_missing, map["lost_candidates"].get<std::size_t>());
  EXPECT_LE(c.new_points, map["lost_candidates"].get<std::size_t>());
}

TEST_F(SessionEviction, TheScansOfAllButTheNewest100KeyframesGoToTheSessionFolder) {
  // A keyframe every 10 cm or 1°: over 100 in the drive and its turn.
  const SessionRun run = map_session(work / "keyframes", 3, 0, 0.1, 1.0);
  const nlohmann::json& map = run.summary["map"];
  const std::size_t keyframes = map["keyframes"];
  ASSERT_GT(keyframes, 110U);  // at most one per scan: 210
  EXPECT_EQ(map["spilled_keyframes"].get<std::size_t>(), keyframes - 100);
  std::size_t files = 0;
  std::size_t points = 0;
  for (const auto& entry : std::filesystem::directory_iterator(run.folder / "keyframes")) {
    ++files;
    points += test::read_ply(entry.path()).size();
  }
  EXPECT_EQ(files, keyframes - 100);
  EXPECT_GT(points, 100 * files);  // downsampled scans, not empty files
  // Every keyframe's pose is still written.
  std::ifstream tum(run.folder / "keyframes.tum");
  std::size_t lines = 0;
  for (std::string line; std::getline(tum, line);) lines += (!line.empty() && line[0] != '#') ? 1 : 0;
  EXPECT_EQ(lines, keyframes);
}

}  // namespace
}  // namespace adit::daemon
