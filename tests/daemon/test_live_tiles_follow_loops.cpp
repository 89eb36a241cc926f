// The live tiles follow the pose graph (map.loops_move_map; docs/LOOPS.md,
// "Live tiles"): on a simulated building floor driven round its loop, tiles
// sent before a closure go again with their points moved, the status's frame
// places the poses by the latest correction and the tiles by none, at the
// end the tiles as a client holds them lie where the exported map does, and
// so do the stored tiles a download after a restart gets. A tiles_graph/ that
// cannot be written costs the session none of its map files.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <linux/fs.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/common/quantile.hpp"
#include "adit/config/load.hpp"
#include "adit/daemon/mapping_stage.hpp"
#include "adit/daemon/session_frame.hpp"
#include "adit/daemon/sessions.hpp"
#include "adit/daemon/tile_spill.hpp"
#include "adit/daemon/tile_store.hpp"
#include "adit/protocol/tile_codec.hpp"
#include "adit/slam/tum.hpp"
#include "daemon_process.hpp"
#include "map_readers.hpp"
#include "point_match.hpp"
#include "run_program.hpp"
#include "sim_sessions.hpp"

namespace adit::daemon {
namespace {

using namespace std::chrono_literals;

// 60 s of a robot round a building floor (seed 1): the drive that
// scripts/bench-loops.sh runs in CI, which closes loops.
std::filesystem::path loop_session() {
  return test::simulated_session("loops-building-60s",
                                 "--scene building --platform robot --sensor VLP-16 --duration 60 --seed 1");
}

// Each point's distance to the nearest of `reference` (up to 0.1 m: a hash of
// 5 cm cells, the 27 around each point).
std::vector<double> nearest_distances(const std::vector<Eigen::Vector3d>& points, const std::vector<test::XyzI>& reference) {
  const auto cell = [](double v) { return static_cast<std::int64_t>(std::floor(v / 0.05)); };
  const auto key = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    return (x & 0x1FFFFF) << 42 | (y & 0x1FFFFF) << 21 | (z & 0x1FFFFF);
  };
  std::unordered_multimap<std::int64_t, Eigen::Vector3d> grid;
  for (const test::XyzI& r : reference) grid.emplace(key(cell(r.x), cell(r.y), cell(r.z)), Eigen::Vector3d(r.x, r.y, r.z));
  std::vector<double> out;
  out.reserve(points.size());
  for (const Eigen::Vector3d& p : points) {
    double best = 0.1;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto [begin, end] = grid.equal_range(key(cell(p.x()) + dx, cell(p.y()) + dy, cell(p.z()) + dz));
          for (auto it = begin; it != end; ++it) best = std::min(best, (it->second - p).norm());
        }
    out.push_back(best);
  }
  return out;
}

// aditd's configuration for the loop drive in a fresh `work` folder: the
// LiDAR's mounting given 3° off in yaw (a bracket turned on its bolts), so the
// odometry drifts round the floor and the loops pull the map back. The graph
// is optimised at each loop (map.loops_optimize_every_s: 0), so that each
// correction reaches the tiles as it is found; with the default's coalesced
// solves more tiles end unsent within their 2 cm, and the worst live point
// lay 25.3 mm from the export against 24.3 mm (decision 062).
std::filesystem::path loop_config(const std::string& name) {
  const std::filesystem::path work = test::binary_dir() / name;
  std::filesystem::remove_all(work);
  std::filesystem::create_directories(work);
  std::string yaml = test::aditd_yaml_for(
      loop_session(), work / "state",
      {"", "", true, "map:\n  loops_move_map: true\n  loops_optimize_every_s: 0\nsession:\n  exports: [ply]\nthreads:\n  lock_memory: false\n"});
  const std::size_t rpy = yaml.find("rpy_deg: [0, 0, 0]");
  if (rpy == std::string::npos) throw std::runtime_error("no mounting rpy_deg in the simulated session's yaml");
  yaml.replace(rpy, 18, "rpy_deg: [0, 0, 3]");
  std::ofstream(work / "aditd.yaml") << yaml;
  return work / "aditd.yaml";
}

TEST(LiveTilesFollowLoops, TilesSentBeforeAClosureGoAgainMovedAndEndWhereTheExportIs) {
  const std::filesystem::path config_file = loop_config("live-tiles-follow-loops");

  std::mutex mutex;
  // Per tile: its first content and its newest (each update's points from its first_point on).
  std::map<std::int64_t, std::vector<protocol::MapPoint>> first, newest;
  std::size_t frames_with_correction = 0;
  Sessions::Outputs outputs;
  outputs.tile = [&](TileUpdate&& update) {
    const std::lock_guard lock(mutex);
    const std::int64_t id = protocol::tile_id(update.key);
    std::vector<protocol::MapPoint>& content = newest[id];
    EXPECT_LE(update.first_point, content.size()) << "tile " << id;
    content.resize(std::min(update.first_point, content.size()));
    content.insert(content.end(), update.points.begin(), update.points.end());
    if (!first.contains(id)) first[id] = content;
    return true;
  };
  Sessions sessions(config::load_config(config_file), outputs);
  const std::string id = sessions.start();
  const auto deadline = std::chrono::steady_clock::now() + 300s;
  std::optional<MapFrame> last_frame;
  while (!sessions.poll() && std::chrono::steady_clock::now() < deadline) {
    // The status's frame: the poses placed by the latest correction, then by
    // gravity's level when the odometry has an up (decision 060); the tiles by
    // the level alone (no prior map): a turn about the first pose's position.
    const StatusSample status = sessions.status_sample();
    if (status.frame && (status.frame->source == kFrameSourceLoops || status.frame->source == kFrameSourceLevel)) {
      last_frame = status.frame;
      EXPECT_EQ(status.frame->tiles_position, (std::array<double, 3>{0, 0, 0}));
      if (status.frame->source == kFrameSourceLoops) {
        EXPECT_EQ(status.frame->tiles_orientation, (std::array<double, 4>{1, 0, 0, 0}));
      }
      // The loop closure's progress (loop_status_t) goes with every status.
      EXPECT_TRUE(status.loops.has_value());
      // With a correction the graph's path (graph_path_t) goes with it. (The
      // poses' transform differs from the tiles' from the first scan on: it
      // carries the map's refinement too, map_frame.hpp.)
      if (status.graph != nullptr) {
        ++frames_with_correction;
        EXPECT_NE(status.frame->position, status.frame->tiles_position);
        if (status.loops) {
          EXPECT_GT(status.loops->accepted, 0) << "a correction comes from a loop";
          EXPECT_GT(status.loops->last_loop_utime, 0);
          EXPECT_GT(status.loops->correction_m + status.loops->correction_deg, 0.0F);
          EXPECT_TRUE(status.loops->moves_map);
        }
      }
    }
    std::this_thread::sleep_for(20ms);
  }
  sessions.stop_and_wait();
  const std::filesystem::path folder = sessions.folder(id);
  // The drive's accelerometer levels the exports; the live tiles are placed by that level.
  const std::optional<Eigen::Isometry3d> level = read_level_frame(folder / "level_frame.json");
  ASSERT_TRUE(level.has_value()) << "no level_frame.json in " << folder;
  ASSERT_TRUE(last_frame.has_value());
  EXPECT_EQ(last_frame->source, kFrameSourceLevel);
  const Eigen::Quaterniond tiles_turn(last_frame->tiles_orientation[0], last_frame->tiles_orientation[1],
                                      last_frame->tiles_orientation[2], last_frame->tiles_orientation[3]);
  EXPECT_LT(tiles_turn.angularDistance(Eigen::Quaterniond(level->linear())), 1e-6)
      << "the status's last frame places the tiles by the level the exports are in";
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(folder / "summary.json"));
  ASSERT_GE(summary["loops"]["accepted"].get<int>(), 1) << "the drive closed no loop";
  EXPECT_TRUE(summary["loops"]["map_moved"].get<bool>());
  EXPECT_GE(summary["loops"]["optimization_iterations"].get<std::size_t>(),
            summary["loops"]["optimizations"].get<std::size_t>()) << "Ceres counts at least one per solve";
  EXPECT_GT(frames_with_correction, 0U);
  // The trajectories are moved with the map files: the map's poses at the
  // keyframes' stamps are where the graph put the keyframes (keyframes.tum).
  for (const char* name : {"trajectory.tum", "map_trajectory.tum"}) {
    std::ifstream in(folder / name);
    std::string first_line;
    std::getline(in, first_line);
    EXPECT_EQ(first_line.rfind("# frame: level (the pose graph's correction", 0), 0U) << name << ": " << first_line;
  }
  const slam::Trajectory map_poses = slam::read_tum(folder / "map_trajectory.tum");
  const slam::Trajectory graph_poses = slam::read_tum(folder / "keyframes.tum");
  ASSERT_GT(graph_poses.size(), 10U);
  std::size_t matched = 0;
  double worst_m = 0.0;
  for (std::size_t k = 0, i = 0; k < graph_poses.size(); ++k) {
    while (i < map_poses.size() && map_poses.stamps[i] < graph_poses.stamps[k] - 1e-4) ++i;
    if (i == map_poses.size() || std::abs(map_poses.stamps[i] - graph_poses.stamps[k]) > 1e-4) continue;
    ++matched;
    worst_m = std::max(worst_m, (map_poses.poses[i].translation() - graph_poses.poses[k].translation()).norm());
  }
  EXPECT_EQ(matched, graph_poses.size());
  EXPECT_LT(worst_m, 1e-4);
  // Tiles the sensor still sees go again anyway, placed by the latest
  // correction; the others are checked and go again if they moved.
  EXPECT_GE(summary["map"]["tiles_checked_for_loops"].get<std::size_t>(),
            summary["map"]["tiles_moved_by_loops"].get<std::size_t>());

  // Tiles sent before a closure and again after it: their first points (a
  // tile's points keep their append order) moved by more than 2 cm.
  std::size_t tiles_moved = 0;
  for (const auto& [tile, before] : first) {
    const std::vector<protocol::MapPoint>& after = newest.at(tile);
    ASSERT_GE(after.size(), before.size());
    double most = 0.0;
    for (std::size_t i = 0; i < before.size(); ++i)
      most = std::max(most, std::hypot(after[i].x - before[i].x, after[i].y - before[i].y, after[i].z - before[i].z));
    tiles_moved += most > 0.02 ? 1 : 0;
  }
  EXPECT_GE(tiles_moved, 1U);

  // What a client holds at the end is the exported map (moved by the graph
  // after its last refinement, which the tiles sent follow at the end too):
  // the same points, each within the 2 cm a tile may move unsent.
  std::vector<Eigen::Vector3d> live;
  for (const auto& [tile, points] : newest)
    for (const protocol::MapPoint& p : points) live.push_back(*level * Eigen::Vector3d(p.x, p.y, p.z));
  const std::vector<test::XyzI> exported = test::read_ply(folder / "map.ply");
  EXPECT_EQ(live.size(), exported.size());
  const std::vector<double> d = nearest_distances(live, exported);
  fmt::print("live tiles against the export: median {:.4f} m, p99 {:.4f} m, max {:.4f} m\n", quantile(d, 0.5),
             quantile(d, 0.99), quantile(d, 1.0));
  // A tile is sent again when the correction moves it by more than
  // kTileMoveM (2 cm), also by the optimisations after the mapping's last
  // flush and the graph's last refinement (MappingStage::follow_final_correction);
  // a few mm more where a tile went to disk and back: the export reads it
  // back whole, its points timed by segment (daemon/tile_spill.hpp), the live
  // tile's new points kept their own times.
  EXPECT_LT(quantile(d, 0.5), 0.005);
  EXPECT_LT(quantile(d, 0.99), 0.01);
  EXPECT_LT(quantile(d, 1.0), MappingStage::kTileMoveM + 0.005);

  // After a restart (a daemon holding nothing of the session) a download is
  // served from the stored tiles: those the graph placed last (tiles_graph/),
  // where the export is, in the graph's frame, which frame_t names.
  ASSERT_TRUE(std::filesystem::is_directory(folder / "tiles_graph")) << "no tiles_graph/ in " << folder;
  Sessions restarted(config::load_config(config_file), Sessions::Outputs{});
  TileStore stored(stored_tile_params(20.0));
  ASSERT_EQ(restarted.load_tiles(id, stored), "");
  std::vector<Eigen::Vector3d> downloaded;
  std::vector<std::uint8_t> frame;
  std::vector<protocol::MapPoint> points;
  for (const auto& [tile_id, tile] : stored.tiles())
    for (std::size_t s = 0; s < tile.segments.size(); ++s) {
      ASSERT_EQ(stored.read_frame(tile, s, frame), "");
      points.clear();
      ASSERT_EQ(protocol::decode_segment(frame, protocol::tile_key(tile_id), tile.params.tile_size_m,
                                         tile.params.quantum_m, tile.params.centred, points),
                "");
      for (const protocol::MapPoint& p : points) downloaded.push_back(*level * Eigen::Vector3d(p.x, p.y, p.z));
    }
  EXPECT_EQ(downloaded.size(), exported.size());
  const std::vector<double> e = nearest_distances(downloaded, exported);
  fmt::print("stored tiles after a restart against the export: median {:.4f} m, max {:.4f} m\n", quantile(e, 0.5),
             quantile(e, 1.0));
  EXPECT_LT(quantile(e, 1.0), 0.002);  // the same points: each quantised to 1 mm in the tile, to float in the file
  const std::optional<MapFrame> placed = restarted.stored_frame(id);
  ASSERT_TRUE(placed.has_value());
  EXPECT_EQ(placed->source, kFrameSourceLevel);
  EXPECT_EQ(placed->tiles_position, (std::array<double, 3>{0, 0, 0}));
  EXPECT_LT(Eigen::Quaterniond(placed->tiles_orientation[0], placed->tiles_orientation[1], placed->tiles_orientation[2],
                               placed->tiles_orientation[3])
                .angularDistance(Eigen::Quaterniond(level->linear())),
            1e-9)
      << "the level the exports are in";
  EXPECT_GT(std::hypot(placed->position[0], placed->position[1], placed->position[2]), 0.0)
      << "the poses are placed by the graph's last correction";
}

// A folder nothing may be written in, not even by root (the ext4 immutable
// flag, as `chattr +i`), lifted again when the test ends.
class ImmutableFolder {
 public:
  explicit ImmutableFolder(std::filesystem::path dir) : dir_(std::move(dir)) {
    std::filesystem::create_directories(dir_);
    set(true);
  }
  ~ImmutableFolder() {
    if (held_) set(false);
  }
  ImmutableFolder(const ImmutableFolder&) = delete;
  ImmutableFolder& operator=(const ImmutableFolder&) = delete;
  bool held() const { return held_; }
  const std::string& problem() const { return problem_; }

 private:
  void set(bool on) {
    const int fd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY);
    int flags = 0;
    if (fd < 0 || ::ioctl(fd, FS_IOC_GETFLAGS, &flags) != 0) {
      problem_ = std::strerror(errno);
    } else {
      flags = on ? (flags | FS_IMMUTABLE_FL) : (flags & ~FS_IMMUTABLE_FL);
      if (::ioctl(fd, FS_IOC_SETFLAGS, &flags) == 0) held_ = on;
      else problem_ = std::strerror(errno);
    }
    if (fd >= 0) ::close(fd);
  }
  std::filesystem::path dir_;
  bool held_ = false;
  std::string problem_;
};

// A tiles_graph/ that cannot be written at the session's end (here: its
// partial folder made immutable; on a payload, a full disk): the map files
// are written all the same, no tiles_graph/ is left, and a download after a
// restart is served from tiles/, in the odometry's frame.
TEST(LiveTilesFollowLoops, AGraphTilesFolderThatCannotBeWrittenCostsNoMapFile) {
  const std::filesystem::path config_file = loop_config("live-tiles-graph-unwritable");
  Sessions sessions(config::load_config(config_file), Sessions::Outputs{});
  const std::string id = sessions.start();
  const std::filesystem::path folder = sessions.folder(id);
  const ImmutableFolder blocked(folder / kGraphTilesPartialFolder);
  if (!blocked.held())
    GTEST_SKIP() << "cannot make a folder immutable here (" << blocked.problem() << "): needs root on ext4";
  const auto deadline = std::chrono::steady_clock::now() + 300s;
  while (!sessions.poll() && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(20ms);
  sessions.stop_and_wait();

  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(folder / "summary.json"));
  ASSERT_GE(summary["loops"]["accepted"].get<int>(), 1) << "the drive closed no loop";
  EXPECT_TRUE(summary["loops"]["map_moved"].get<bool>());
  const std::vector<test::XyzI> exported = test::read_ply(folder / "map.ply");
  EXPECT_GT(exported.size(), 100'000U);
  EXPECT_FALSE(std::filesystem::exists(folder / kGraphTilesFolder));
  EXPECT_TRUE(std::filesystem::is_empty(folder / kGraphTilesPartialFolder));

  Sessions restarted(config::load_config(config_file), Sessions::Outputs{});
  TileStore stored(stored_tile_params(20.0));
  ASSERT_EQ(restarted.load_tiles(id, stored), "");
  EXPECT_EQ(stored.total_points(), static_cast<std::int64_t>(exported.size())) << "tiles/ holds the map's points";
  // tiles/ is in the odometry frame: placed by gravity's level alone, not the graph's correction.
  const std::optional<MapFrame> placed = restarted.stored_frame(id);
  ASSERT_TRUE(placed.has_value());
  EXPECT_EQ(placed->source, kFrameSourceLevel);
  EXPECT_EQ(placed->orientation, placed->tiles_orientation);
  EXPECT_EQ(placed->position, placed->tiles_position);
}

}  // namespace
}  // namespace adit::daemon
