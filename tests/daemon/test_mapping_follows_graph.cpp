// The mapping stage's live tiles placed by the loop closure's correction
// (MappingStage::follow_graph, map.loops_move_map; docs/LOOPS.md "Live
// tiles"): a tile sent before a correction is posted goes again, unchanged in
// content, with every point moved by the correction at its scan's time; one
// the correction moves by less than MappingStage::kTileMoveM is not sent again.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <mutex>
#include <thread>

#include "adit/daemon/mapping_stage.hpp"
#include "map_slots.hpp"

namespace adit::daemon {
namespace {

using namespace std::chrono_literals;

Eigen::Isometry3d shifted(double x, double y) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(x, y, 0.0);
  return t;
}

// A wall 5 m ahead of a still sensor, 0.1 m apart: the same voxels every scan.
void fill_wall(MapSlot& slot, std::int64_t stamp_ns) {
  slot.stamp_ns = stamp_ns;
  slot.pose = Eigen::Isometry3d::Identity();
  slot.valid = true;
  slot.points.clear();
  slot.times_s.clear();
  slot.intensities.clear();
  for (int i = -30; i <= 30; ++i)
    for (int j = 0; j <= 20; ++j) {
      slot.points.emplace_back(5.0F, 0.1F * static_cast<float>(i), 0.1F * static_cast<float>(j) - 1.0F);
      slot.times_s.push_back(0.0F);
      slot.intensities.push_back(10.0F);
    }
}

struct Sent {
  std::mutex mutex;
  std::map<slam::TileCoord, std::vector<std::vector<slam::MapSample>>> tiles;  // every send of each tile
  std::map<slam::TileCoord, std::vector<std::chrono::steady_clock::time_point>> when;  // and when it went
  std::size_t count() {
    const std::lock_guard lock(mutex);
    std::size_t n = 0;
    for (const auto& [coord, sends] : tiles) n += sends.size();
    return n;
  }
};

struct StageRun {
  Sent sent;
  PipelineStats stats;
  std::function<std::uint64_t()> backlog;  // the tile sink's backlog (MappingStage::limit_tile_backlog)
  bool grid = false;  // with the live grid, its patches as last sent:
  std::mutex grid_mutex;
  std::map<slam::GridPatchCoord, std::vector<std::int8_t>> patches;
  int patch_cells = 0;
  float resolution_m = 0.0F;
  bool merge_revisits = true;                                   // map.merge_revisits
  std::int64_t third_ns = 3'000'000'000;                        // the third scan's time
  Eigen::Isometry3d third_pose = Eigen::Isometry3d::Identity();  // and its pose
  std::size_t map_points = 0;                                   // after the run
  // With `second`: once the third scan's tiles went out, `second` is posted
  // and a fourth scan at 4 s, 3 m to the left, is mapped (a fifth there
  // too: it adds nothing, the same voxels); `mid` is each
  // tile's content as sent before the stage ends (its last flush).
  std::optional<slam::CorrectionTrack> second;
  std::map<slam::TileCoord, std::vector<slam::MapSample>> mid;

  // The occupied cells' centres (x, y), map frame.
  std::vector<Eigen::Vector2f> occupied() {
    const std::lock_guard lock(grid_mutex);
    std::vector<Eigen::Vector2f> out;
    for (const auto& [c, cells] : patches)
      for (int row = 0; row < patch_cells; ++row)
        for (int col = 0; col < patch_cells; ++col)
          if (cells[static_cast<std::size_t>(row * patch_cells + col)] == slam::kGridOccupied)
            out.emplace_back((static_cast<float>(c.x * patch_cells + col) + 0.5F) * resolution_m,
                             (static_cast<float>(c.y * patch_cells + row) + 0.5F) * resolution_m);
    return out;
  }
};

// Scans at 1 s and 2 s; once their tiles went out, `correction` is posted (if
// any); a third scan at 3 s; then the stage ends (its last flush).
void run_stage(StageRun& run, const std::optional<slam::CorrectionTrack>& correction) {
  config::Config config;
  config.map.refine = false;  // the poses as given
  config.map.min_hits = 1;
  config.map.publish_period_s = 0.05;
  config.grid.enabled = run.grid;
  config.grid.publish_period_s = 0.05;
  config.map.merge_revisits = run.merge_revisits;
  std::atomic<bool> stop{false};
  constexpr std::size_t kMaxPoints = 2000;
  Handoff<MapSlot> scans(4, Overflow::wait, test::map_slot_with_room(kMaxPoints));
  CorrectionBoard board;
  MappingStage stage(
      config, slam::OdometryConfig{}, scans, kMaxPoints,
      [&run](const slam::TileCoord& coord, std::size_t first, std::span<const slam::MapSample> samples) {
        const std::lock_guard lock(run.sent.mutex);
        std::vector<std::vector<slam::MapSample>>& sends = run.sent.tiles[coord];
        // The tile's content after this send: what it held before `first`, then `samples`.
        std::vector<slam::MapSample> content = sends.empty() ? std::vector<slam::MapSample>{} : sends.back();
        EXPECT_LE(first, content.size());
        content.resize(std::min(first, content.size()));
        content.insert(content.end(), samples.begin(), samples.end());
        sends.push_back(std::move(content));
        run.sent.when[coord].push_back(std::chrono::steady_clock::now());
        return true;
      },
      run.stats, stop);
  stage.follow_graph(&board);
  stage.limit_tile_backlog(run.backlog);
  run.patch_cells = config.grid.patch_cells;
  run.resolution_m = static_cast<float>(config.grid.resolution_m);
  stage.publish_grid_to([&run](slam::GridPatchCoord c, std::int32_t, std::span<const std::int8_t> cells, std::size_t) {
    const std::lock_guard lock(run.grid_mutex);
    run.patches[c].assign(cells.begin(), cells.end());
  });
  stage.start();
  const auto push = [&](std::int64_t stamp_ns, const Eigen::Isometry3d& pose = Eigen::Isometry3d::Identity()) {
    MapSlot* slot = scans.acquire_or_wait([] { return true; });
    ASSERT_NE(slot, nullptr);
    fill_wall(*slot, stamp_ns);
    slot->pose = pose;
    scans.publish(slot);
  };
  push(1'000'000'000);
  push(2'000'000'000);
  for (int i = 0; i < 200 && run.sent.count() == 0; ++i) std::this_thread::sleep_for(10ms);
  ASSERT_GT(run.sent.count(), 0U) << "the first scan's tiles never went out";
  if (correction) board.post(*correction);
  push(run.third_ns, run.third_pose);
  if (run.second) {
    // The first correction taken (its tiles checked), then the second posted.
    for (int i = 0; i < 500 && run.stats.tiles_checked_for_loops.load() == 0; ++i) std::this_thread::sleep_for(10ms);
    board.post(*run.second);
    push(4'000'000'000, shifted(0, 3.0));
    push(5'000'000'000, shifted(0, 3.0));  // a scan is mapped once the next one's pose came
    const auto fourth_sent = [&run] {
      const std::lock_guard lock(run.sent.mutex);
      for (const auto& [coord, sends] : run.sent.tiles)
        for (const slam::MapSample& s : sends.back())
          if (s.time_s == 4.0) return true;
      return false;
    };
    for (int i = 0; i < 500 && !fourth_sent(); ++i) std::this_thread::sleep_for(10ms);
    std::this_thread::sleep_for(200ms);  // four more flushes: a correction due would have been taken
    const std::lock_guard lock(run.sent.mutex);
    for (const auto& [coord, sends] : run.sent.tiles) run.mid[coord] = sends.back();
  }
  scans.close();
  stage.join();
  run.map_points = stage.map().size();
}

TEST(MappingFollowsGraph, TilesSentBeforeACorrectionGoAgainMovedByIt) {
  // The graph moved the keyframes at 1 s and 3 s by 0.5 m and 0.7 m in y;
  // the wall's points are all the first scan's (the later ones hit the same voxels).
  const std::vector<std::int64_t> stamps{1'000'000'000, 3'000'000'000};
  const std::vector<Eigen::Isometry3d> odometry{Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity()};
  const slam::CorrectionTrack track(stamps, std::vector{shifted(0, 0.5), shifted(0, 0.7)}, odometry);
  StageRun run;
  run_stage(run, track);
  ASSERT_FALSE(run.sent.tiles.empty());
  std::size_t resent = 0;
  for (const auto& [coord, sends] : run.sent.tiles) {
    ASSERT_GE(sends.size(), 2U) << "tile " << coord.x << " " << coord.y << " " << coord.z << " not sent again";
    const std::vector<slam::MapSample>& first = sends.front();
    const std::vector<slam::MapSample>& last = sends.back();
    ASSERT_EQ(last.size(), first.size());  // the same voxels: only moved
    for (std::size_t i = 0; i < first.size(); ++i) {
      const Eigen::Vector3d want =
          track.at(static_cast<std::int64_t>(first[i].time_s * 1e9)) * first[i].position.cast<double>();
      EXPECT_LT((last[i].position.cast<double>() - want).norm(), 1e-5);
      EXPECT_NEAR(last[i].position.y() - first[i].position.y(), 0.5, 1e-5);  // every point is the first scan's
    }
    ++resent;
  }
  EXPECT_EQ(run.stats.tiles_moved_by_loops.load(), resent);
  EXPECT_GE(run.stats.tiles_checked_for_loops.load(), resent);
}

// While more than kTileBacklogPoints wait for the tile sink's consumer (the
// LCM thread), tiles a correction moved are not sent again; new content still
// goes. The final flush waits for the backlog to drain, then sends them all.
TEST(MappingFollowsGraph, MovedTilesWaitWhileTheTileSinksBacklogIsLong) {
  const std::vector<std::int64_t> stamps{1'000'000'000, 3'000'000'000};
  const std::vector<Eigen::Isometry3d> odometry{Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity()};
  const slam::CorrectionTrack track(stamps, std::vector{shifted(0, 0.5), shifted(0, 0.7)}, odometry);
  const auto drained_at = std::chrono::steady_clock::now() + 1500ms;
  std::atomic<int> asked{0};
  StageRun run;
  run.backlog = [&]() -> std::uint64_t {
    ++asked;
    return std::chrono::steady_clock::now() < drained_at ? MappingStage::kTileBacklogPoints + 1 : 0;
  };
  run_stage(run, track);
  EXPECT_GT(asked.load(), 0);
  ASSERT_FALSE(run.sent.tiles.empty());
  for (const auto& [coord, sends] : run.sent.tiles) {
    ASSERT_GE(sends.size(), 2U) << "a moved tile was never sent again";
    const auto& when = run.sent.when[coord];
    EXPECT_LT(when.front(), drained_at) << "the first content went while the backlog was long";
    EXPECT_GE(when.back(), drained_at) << "a moved tile went again before the backlog drained";
    EXPECT_NEAR(sends.back().front().position.y() - sends.front().front().position.y(), 0.5, 1e-5);
  }
  EXPECT_EQ(run.stats.tiles_moved_by_loops.load(), run.sent.tiles.size());
}

TEST(MappingFollowsGraph, ACorrectionBelowTheThresholdSendsNothingAgain) {
  const std::vector<std::int64_t> stamps{1'000'000'000};
  const double small = 0.5 * MappingStage::kTileMoveM;
  const slam::CorrectionTrack track(stamps, std::vector{shifted(small, 0)}, std::vector{Eigen::Isometry3d::Identity()});
  StageRun run;
  run_stage(run, track);
  EXPECT_EQ(run.stats.tiles_moved_by_loops.load(), 0U);
  EXPECT_GT(run.stats.tiles_checked_for_loops.load(), 0U);
  for (const auto& [coord, sends] : run.sent.tiles) EXPECT_EQ(sends.size(), 1U);  // sent once, as measured
  StageRun without;
  run_stage(without, std::nullopt);
  EXPECT_EQ(without.stats.tiles_checked_for_loops.load(), 0U);
  EXPECT_EQ(without.sent.count(), run.sent.count());
}

// The live grid goes on where the tiles are: scans mapped after a correction
// are placed by it (the first scan was mapped before it, the second and the
// third after), and the cells put before stay where they were.
TEST(MappingFollowsGraph, ScansAfterACorrectionGoIntoTheGridPlacedByIt) {
  const std::vector<std::int64_t> stamps{1'000'000'000, 3'000'000'000};
  const std::vector<Eigen::Isometry3d> odometry{Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity()};
  const slam::CorrectionTrack track(stamps, std::vector{shifted(0, 0.7), shifted(0, 0.7)}, odometry);
  const auto wall_span = [](StageRun& run) {
    float low = 1e9F, high = -1e9F;
    std::size_t n = 0;
    for (const Eigen::Vector2f& c : run.occupied()) {
      EXPECT_NEAR(c.x(), 5.0F, 0.1F) << "an obstacle off the wall at (" << c.x() << ", " << c.y() << ")";
      low = std::min(low, c.y());
      high = std::max(high, c.y());
      ++n;
    }
    EXPECT_GT(n, 30U);
    return std::pair{low, high};
  };
  StageRun followed;
  followed.grid = true;
  run_stage(followed, track);
  const auto [low, high] = wall_span(followed);
  EXPECT_NEAR(high, 3.0F + 0.7F, 0.1F) << "the later scans' wall, moved by the correction";
  EXPECT_NEAR(low, -3.0F, 0.1F) << "the first scan's wall, where it was put";

  StageRun unmoved;
  unmoved.grid = true;
  run_stage(unmoved, std::nullopt);
  const auto [low0, high0] = wall_span(unmoved);
  EXPECT_NEAR(high0, 3.0F, 0.1F);
  EXPECT_NEAR(low0, -3.0F, 0.1F);
}

// A revisit (map.merge_revisits): the third scan sees the same wall 97 s
// later with the odometry 0.5 m off along x, which the graph's correction
// takes back. Its points lie, by the correction, where the first scan's are:
// none is added. Without merging they would all be added again, 0.5 m away.
TEST(MappingFollowsGraph, ARevisitAddsNothingThatAnEarlierPassMapped) {
  const std::vector<std::int64_t> stamps{1'000'000'000, 100'000'000'000};
  const std::vector<Eigen::Isometry3d> graph{Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity()};
  const slam::CorrectionTrack track(stamps, graph, std::vector{Eigen::Isometry3d::Identity(), shifted(0.5, 0)});
  StageRun merged;
  merged.third_ns = stamps[1];
  merged.third_pose = shifted(0.5, 0);
  run_stage(merged, track);
  constexpr std::size_t kWall = 61 * 21;
  EXPECT_EQ(merged.map_points, kWall);
  EXPECT_EQ(merged.stats.revisit_points.load(), kWall);

  StageRun unmerged;
  unmerged.merge_revisits = false;
  unmerged.third_ns = stamps[1];
  unmerged.third_pose = shifted(0.5, 0);
  run_stage(unmerged, track);
  EXPECT_EQ(unmerged.map_points, 2 * kWall);
  EXPECT_EQ(unmerged.stats.revisit_points.load(), 0U);
}

}  // namespace
}  // namespace adit::daemon

namespace adit::daemon {
namespace {

// Where a tile holds the fourth scan's points, against where the scan put
// them: its wall's far end (6 m before any correction), less 6 m.
double fourth_scan_offset(const std::map<slam::TileCoord, std::vector<slam::MapSample>>& tiles) {
  double far = -1e9;
  for (const auto& [coord, samples] : tiles)
    for (const slam::MapSample& s : samples)
      if (s.time_s == 4.0) far = std::max(far, static_cast<double>(s.position.y()));
  return far - 6.0;
}

// The live tiles take a new correction at once when it moves the sensor's
// place by more than kPlacementMoveM; a smaller one waits (kPlacementPeriodS,
// or the end), the scans meanwhile placed as the tiles are (decision 074).
TEST(MappingFollowsGraph, ACorrectionThatBarelyMovesTheSensorsPlaceWaitsForTheEnd) {
  const std::vector<std::int64_t> stamps{1'000'000'000, 3'000'000'000};
  const std::vector<Eigen::Isometry3d> odometry{Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity()};
  const slam::CorrectionTrack first(stamps, std::vector{shifted(0, 0.5), shifted(0, 0.7)}, odometry);
  for (const double head : {0.03, 0.10}) {  // the second correction at 3 s and after: 3 or 10 cm more
    ASSERT_LT(0.03, MappingStage::kPlacementMoveM);
    ASSERT_GT(0.10, MappingStage::kPlacementMoveM);
    StageRun run;
    run.second = slam::CorrectionTrack(stamps, std::vector{shifted(0, 0.5), shifted(0, 0.7 + head)}, odometry);
    run_stage(run, first);
    ASSERT_FALSE(run.mid.empty());
    const double taken = head < MappingStage::kPlacementMoveM ? 0.7 : 0.7 + head;
    EXPECT_NEAR(fourth_scan_offset(run.mid), taken, 1e-4) << "head " << head;
    std::map<slam::TileCoord, std::vector<slam::MapSample>> last;
    for (const auto& [coord, sends] : run.sent.tiles) last[coord] = sends.back();
    EXPECT_NEAR(fourth_scan_offset(last), 0.7 + head, 1e-4) << "at the end, every tile follows the latest";
  }
}

}  // namespace
}  // namespace adit::daemon
