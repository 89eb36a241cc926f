#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "adit/slam/keyframes.hpp"
#include "adit/slam/tiled_map.hpp"

namespace adit::slam {
namespace {

TEST(TiledVoxelMap, KeepsTheFirstPointPerVoxel) {
  TiledVoxelMap map({20.0F, 0.05F, 1});
  const std::vector<Eigen::Vector3f> first{{1.01F, 2.01F, 0.51F}, {1.04F, 2.04F, 0.54F}, {1.06F, 2.01F, 0.51F}};
  EXPECT_EQ(map.add(first, std::vector<float>{10, 20, 30}, 5.0), 2U);  // the second shares the first's voxel
  const std::vector<Eigen::Vector3f> again{{1.02F, 2.02F, 0.52F}};
  EXPECT_EQ(map.add(again, {}, 6.0), 0U);
  ASSERT_EQ(map.size(), 2U);
  const auto tile = map.tile({0, 0, 0});
  ASSERT_EQ(tile.size(), 2U);
  EXPECT_FLOAT_EQ(tile[0].position.x(), 1.01F);
  EXPECT_FLOAT_EQ(tile[0].intensity, 10.0F);
  EXPECT_DOUBLE_EQ(tile[0].time_s, 5.0);
  EXPECT_FLOAT_EQ(tile[1].intensity, 30.0F);
}

TEST(TiledVoxelMap, BinsPointsIntoTilesByFloorAndReportsChangesOnce) {
  TiledVoxelMap map({20.0F, 0.5F, 1});
  const std::vector<Eigen::Vector3f> points{{-0.1F, 0.0F, 0.0F}, {19.9F, 0.0F, 0.0F}, {20.0F, 0.0F, -20.1F}};
  EXPECT_EQ(map.add(points, {}, 0.0), 3U);
  const std::vector<TileCoord> changed = map.take_changed();
  const std::vector<TileCoord> expected{{-1, 0, 0}, {0, 0, 0}, {1, 0, -2}};
  EXPECT_EQ(changed, expected);
  EXPECT_TRUE(map.take_changed().empty());
  EXPECT_EQ(map.tile_count(), 3U);
  // A point in an occupied voxel changes nothing.
  EXPECT_EQ(map.add(std::vector<Eigen::Vector3f>{{19.8F, 0.1F, 0.1F}}, {}, 1.0), 0U);
  EXPECT_TRUE(map.take_changed().empty());
}

TEST(TiledVoxelMap, KeepsEveryDistinctVoxelOnceThroughManyGrowths) {
  TiledVoxelMap map({20.0F, 0.1F, 1});
  std::vector<Eigen::Vector3f> grid;  // 60 × 60 × 30 distinct voxel centres in one tile
  for (int i = 0; i < 60; ++i)
    for (int j = 0; j < 60; ++j)
      for (int k = 0; k < 30; ++k) grid.emplace_back(0.05F + 0.1F * i, 0.05F + 0.1F * j, 0.05F + 0.1F * k);
  EXPECT_EQ(map.add(grid, {}, 0.0), grid.size());
  EXPECT_EQ(map.add(grid, {}, 1.0), 0U);  // every voxel is taken now
  EXPECT_EQ(map.size(), grid.size());
  EXPECT_EQ(map.tile({0, 0, 0}).size(), grid.size());
}

TEST(TiledVoxelMap, AVoxelEntersTheMapOnlyOnceHitMinHitsTimes) {
  TiledVoxelMap map({20.0F, 0.05F, 2});
  const std::vector<Eigen::Vector3f> first{{1.01F, 1.01F, 1.01F}, {5.0F, 5.0F, 5.0F}};
  EXPECT_EQ(map.add(first, std::vector<float>{7, 8}, 1.0), 0U);  // seen once: candidates only
  EXPECT_EQ(map.size(), 0U);
  EXPECT_EQ(map.candidates(), 2U);
  EXPECT_TRUE(map.take_changed().empty());
  // The first voxel is hit again: its first point (not the new one) enters the map.
  EXPECT_EQ(map.add(std::vector<Eigen::Vector3f>{{1.04F, 1.02F, 1.03F}}, {}, 2.0), 1U);
  ASSERT_EQ(map.tile({0, 0, 0}).size(), 1U);
  EXPECT_FLOAT_EQ(map.tile({0, 0, 0})[0].position.x(), 1.01F);
  EXPECT_FLOAT_EQ(map.tile({0, 0, 0})[0].intensity, 7.0F);
  EXPECT_DOUBLE_EQ(map.tile({0, 0, 0})[0].time_s, 1.0);
  EXPECT_EQ(map.take_changed(), (std::vector<TileCoord>{{0, 0, 0}}));
  // Further hits change nothing.
  EXPECT_EQ(map.add(std::vector<Eigen::Vector3f>{{1.02F, 1.02F, 1.02F}}, {}, 3.0), 0U);
  EXPECT_TRUE(map.take_changed().empty());
  EXPECT_EQ(map.size(), 1U);
}

TEST(TiledVoxelMap, SkipsNonFinitePoints) {
  TiledVoxelMap map({20.0F, 0.05F, 1});
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(map.add(std::vector<Eigen::Vector3f>{{nan, 0, 0}, {0, inf, 0}, {1, 1, 1}}, {}, 0.0), 1U);
  EXPECT_EQ(map.tile_count(), 1U);
}

TEST(TiledVoxelMap, HoldsSaysWhichPointsFallInAConfirmedOrStoredVoxel) {
  TiledVoxelMap map({20.0F, 0.1F, 2});
  const std::vector<Eigen::Vector3f> twice{{1.01F, 1.01F, 1.01F}};
  map.add(twice, {}, 1.0);
  map.add(twice, {}, 2.0);                                   // confirmed
  map.add(std::vector<Eigen::Vector3f>{{3.01F, 1.01F, 1.01F}}, {}, 3.0);  // a candidate only
  map.add(std::vector<Eigen::Vector3f>{{25.0F, 1.0F, 1.0F}}, {}, 4.0);
  map.add(std::vector<Eigen::Vector3f>{{25.0F, 1.0F, 1.0F}}, {}, 5.0);
  map.evict({1, 0, 0});
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<Eigen::Vector3f> probes{{1.09F, 1.05F, 1.0F},  // the confirmed voxel
                                            {1.11F, 1.05F, 1.0F},  // beside it
                                            {3.05F, 1.05F, 1.05F}, // the candidate's
                                            {25.0F, 1.0F, 1.0F},   // in the evicted tile
                                            {nan, 0.0F, 0.0F},
                                            {-5.0F, 1.0F, 1.0F}};  // no tile
  std::vector<std::uint8_t> held;
  map.holds(probes, held);
  EXPECT_EQ(held, (std::vector<std::uint8_t>{1, 0, 0, 0, 0, 0}));
  const TiledVoxelMap::Evicted out = map.evict({0, 0, 0});
  map.restore({0, 0, 0}, out.points);  // the confirmed voxel now a stored bit
  map.holds(probes, held);
  EXPECT_EQ(held, (std::vector<std::uint8_t>{1, 0, 0, 0, 0, 0}));
  map.holds(probes, held, 1);  // a voxel beside a held one counts too
  EXPECT_EQ(held, (std::vector<std::uint8_t>{1, 1, 0, 0, 0, 0}));
}

TEST(TiledVoxelMap, RejectsUnusableSizes) {
  EXPECT_NE(tiled_map_config_problem({0.0F, 0.05F}), "");
  EXPECT_NE(tiled_map_config_problem({20.0F, -1.0F}), "");
  EXPECT_NE(tiled_map_config_problem({20.0F, 0.001F}), "");  // 20 000 voxels per edge
  EXPECT_EQ(tiled_map_config_problem({20.0F, 0.05F}), "");
  EXPECT_THROW(TiledVoxelMap({20.0F, 0.0F}), std::invalid_argument);
}

TEST(KeyframeSelector, TakesTheFirstPoseAndThenEveryMetreOrTenDegrees) {
  KeyframeSelector selector({1.0, 10.0});
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  EXPECT_TRUE(selector.take(pose));
  pose.translation().x() = 0.9;
  EXPECT_FALSE(selector.take(pose));
  pose.translation().x() = 1.01;
  EXPECT_TRUE(selector.take(pose));
  pose.linear() = Eigen::AngleAxisd(9.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_FALSE(selector.take(pose));
  pose.linear() = Eigen::AngleAxisd(10.5 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_TRUE(selector.take(pose));
}

// A 10 × 10 × 4 block of distinct voxel centres (5 cm) inside tile (0, 0, 0).
std::vector<Eigen::Vector3f> block(float x0) {
  std::vector<Eigen::Vector3f> out;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j)
      for (int k = 0; k < 4; ++k) out.emplace_back(x0 + 0.025F + 0.05F * i, 0.025F + 0.05F * j, 0.025F + 0.05F * k);
  return out;
}

TEST(TiledVoxelMapEviction, EvictHandsOutTheConfirmedPointsAndLosesOnlyUnconfirmedCandidates) {
  TiledVoxelMap map({20.0F, 0.05F, 2});
  const std::vector<Eigen::Vector3f> twice = block(1.0F);  // hit twice: confirmed
  const std::vector<Eigen::Vector3f> once = block(5.0F);   // hit once: candidates
  map.add(twice, {}, 1.0);
  map.add(twice, {}, 2.0);
  map.add(once, {}, 3.0);
  map.add(std::vector<Eigen::Vector3f>{{30.0F, 1.0F, 1.0F}, {30.0F, 1.0F, 1.0F}}, {}, 3.0);  // tile (1, 0, 0)
  ASSERT_EQ(map.size(), twice.size() + 1);
  const std::size_t bytes_before = map.memory_bytes();

  const TiledVoxelMap::Evicted evicted = map.evict({0, 0, 0});
  EXPECT_EQ(evicted.points.size(), twice.size());
  EXPECT_TRUE(evicted.changed);  // never taken by take_changed: the caller still owes it to the publisher
  EXPECT_DOUBLE_EQ(evicted.points.front().time_s, 1.0);
  EXPECT_EQ(map.lost_candidates(), once.size());
  EXPECT_EQ(map.size(), twice.size() + 1);  // evicted points still belong to the map
  EXPECT_EQ(map.resident_points(), 1U);
  EXPECT_EQ(map.tile_count(), 2U);
  EXPECT_EQ(map.resident_tile_count(), 1U);
  EXPECT_TRUE(map.is_evicted({0, 0, 0}));
  EXPECT_EQ(map.evicted_points({0, 0, 0}), twice.size());
  EXPECT_EQ(map.evicted_coords(), (std::vector<TileCoord>{{0, 0, 0}}));
  EXPECT_EQ(map.tile_coords(), (std::vector<TileCoord>{{1, 0, 0}}));
  EXPECT_TRUE(map.tile({0, 0, 0}).empty());
  EXPECT_LT(map.memory_bytes(), bytes_before / 4);
  EXPECT_EQ(map.take_changed(), (std::vector<TileCoord>{{1, 0, 0}}));  // the evicted one is not reported twice
  EXPECT_TRUE(map.evict({0, 0, 0}).points.empty());  // not resident any more
  EXPECT_FALSE(map.evict({7, 7, 7}).changed);
}

TEST(TiledVoxelMapEviction, PointsInAnEvictedTileAreSkippedUntilItIsRestored) {
  TiledVoxelMap map({20.0F, 0.05F, 1});
  const std::vector<Eigen::Vector3f> points = block(1.0F);
  map.add(points, {}, 1.0);
  const std::vector<MapSample> stored = map.evict({0, 0, 0}).points;
  EXPECT_EQ(map.evicted_hit_by(points), (std::vector<TileCoord>{{0, 0, 0}}));
  EXPECT_TRUE(map.evicted_hit_by(std::vector<Eigen::Vector3f>{{25.0F, 0.0F, 0.0F}}).empty());
  EXPECT_EQ(map.add(points, {}, 2.0), 0U);
  EXPECT_EQ(map.dropped_in_evicted(), points.size());
  EXPECT_EQ(map.tile_count(), 1U);  // no second copy of the tile was started
  EXPECT_EQ(map.size(), points.size());
}

TEST(TiledVoxelMapEviction, ARestoredTileContinuesWithoutDuplicatingItsVoxels) {
  TiledVoxelMap map({20.0F, 0.05F, 2});
  const std::vector<Eigen::Vector3f> points = block(1.0F);
  map.add(points, {}, 1.0);
  map.add(points, {}, 2.0);
  map.take_changed();
  const std::size_t bytes_before = map.memory_bytes();
  const std::vector<MapSample> stored = map.evict({0, 0, 0}).points;

  map.restore({0, 0, 0}, stored);
  EXPECT_FALSE(map.is_evicted({0, 0, 0}));
  EXPECT_EQ(map.size(), points.size());
  EXPECT_TRUE(map.tile({0, 0, 0}).empty());  // the stored points stay the caller's
  EXPECT_EQ(map.stored_points({0, 0, 0}), points.size());
  EXPECT_EQ(map.resident_points(), 0U);
  EXPECT_LT(map.memory_bytes(), bytes_before / 10);  // a bit per stored voxel, not a candidate and a point
  EXPECT_TRUE(map.take_changed().empty());  // restoring is not a change: the content is what was published
  // The same voxels, hit once or many times more: nothing new.
  EXPECT_EQ(map.add(points, {}, 3.0), 0U);
  EXPECT_EQ(map.add(points, {}, 4.0), 0U);
  EXPECT_EQ(map.size(), points.size());
  // A new voxel still needs min_hits hits.
  const std::vector<Eigen::Vector3f> fresh{{9.0F, 9.0F, 9.0F}};
  EXPECT_EQ(map.add(fresh, {}, 5.0), 0U);
  EXPECT_EQ(map.add(fresh, {}, 6.0), 1U);
  EXPECT_EQ(map.size(), points.size() + 1);
  EXPECT_EQ(map.take_changed(), (std::vector<TileCoord>{{0, 0, 0}}));
  ASSERT_EQ(map.tile({0, 0, 0}).size(), 1U);  // only what is new since the restore
  EXPECT_FLOAT_EQ(map.tile({0, 0, 0})[0].position.x(), 9.0F);
  // A resident tile is not replaced by restore().
  map.restore({0, 0, 0}, {});
  EXPECT_EQ(map.stored_points({0, 0, 0}), points.size());
  // Evicted again: out go the new points; the tile's count is the stored part plus them.
  const TiledVoxelMap::Evicted again = map.evict({0, 0, 0});
  EXPECT_EQ(again.points.size(), 1U);
  EXPECT_EQ(map.evicted_points({0, 0, 0}), points.size() + 1);
  EXPECT_EQ(map.size(), points.size() + 1);
}

TEST(TiledVoxelMapEviction, StoredVoxelsAreRecognisedInEveryBlockOfABigTile) {
  // 1 cm voxels in a 12 m tile: 1200 voxels per edge, 150 blocks per edge; points spread over all of it.
  TiledVoxelMap map({12.0F, 0.01F, 1});
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j)
      points.emplace_back(0.005F + 0.3F * static_cast<float>(i), 0.005F + 0.3F * static_cast<float>(j),
                          11.995F - 0.29F * static_cast<float>((i * 7 + j) % 41));
  ASSERT_EQ(map.add(points, {}, 0.0), points.size());
  std::vector<MapSample> stored = map.evict({0, 0, 0}).points;
  map.restore({0, 0, 0}, stored);
  EXPECT_EQ(map.add(points, {}, 1.0), 0U);
  // The voxels next to each stored one (1 cm away on every axis) are free.
  std::vector<Eigen::Vector3f> neighbours;
  for (const Eigen::Vector3f& p : points) neighbours.push_back(p + Eigen::Vector3f(0.01F, 0.01F, -0.01F));
  EXPECT_EQ(map.add(neighbours, {}, 2.0), neighbours.size());
}

TEST(TiledVoxelMapEviction, ARestoredCopyWithTwoPointsInOneVoxelCountsBoth) {
  TiledVoxelMap map({20.0F, 0.05F, 1});
  map.add(std::vector<Eigen::Vector3f>{{1.01F, 1.01F, 1.01F}}, {}, 1.0);
  map.evict({0, 0, 0});
  // A decoded copy can put two points into one voxel (1 mm quantisation at a face).
  const std::vector<MapSample> copy{{Eigen::Vector3f(1.01F, 1.01F, 1.01F), 1.0F, 1.0},
                                    {Eigen::Vector3f(1.02F, 1.02F, 1.02F), 2.0F, 1.0}};
  map.restore({0, 0, 0}, copy);
  EXPECT_EQ(map.size(), 2U);
  EXPECT_EQ(map.stored_points({0, 0, 0}), 2U);
  EXPECT_EQ(map.add(std::vector<Eigen::Vector3f>{{1.03F, 1.03F, 1.03F}}, {}, 2.0), 0U);
}

TEST(TileEviction, ATileHoldingMoreThanCompactVoxelsIsCrowded) {
  TiledVoxelMap map({20.0F, 0.05F, 2});
  map.add(block(1.0F), {}, 0.0);                                    // 400 voxels in tile (0, 0, 0), candidates only
  map.add(std::vector<Eigen::Vector3f>{{21.0F, 1.0F, 1.0F}}, {}, 0.0);  // 1 in tile (1, 0, 0)
  EXPECT_EQ(map.held_voxels({0, 0, 0}), 400U);
  EXPECT_EQ(TileEviction({50.0F, 20, 399}).crowded_tiles(map), (std::vector<TileCoord>{{0, 0, 0}}));
  EXPECT_TRUE(TileEviction({50.0F, 20, 400}).crowded_tiles(map).empty());
  EXPECT_TRUE(TileEviction({50.0F, 20, 0}).crowded_tiles(map).empty());
  // Compacted (evicted and restored at once), it holds nothing but the bits of its stored voxels.
  std::vector<MapSample> stored = map.evict({0, 0, 0}).points;
  map.restore({0, 0, 0}, stored);
  EXPECT_EQ(map.held_voxels({0, 0, 0}), 0U);
}

TEST(TileEviction, OverItsBudgetTheMapCompactsItsLargestTilesDownToThreeQuartersOfIt) {
  TiledVoxelMap map({20.0F, 0.05F, 2});
  map.add(block(1.0F), {}, 0.0);  // tile (0, 0, 0): 400 voxels
  for (int b = 0; b < 10; ++b) map.add(block(21.0F + 0.5F * static_cast<float>(b)), {}, 0.0);  // (1, 0, 0): 4,000
  map.add(std::vector<Eigen::Vector3f>{{41.0F, 1.0F, 1.0F}}, {}, 0.0);  // (2, 0, 0): 1
  const std::size_t total = map.memory_bytes();
  const TileCoord small{0, 0, 0};
  const TileCoord large{1, 0, 0};
  ASSERT_GT(map.compactable_bytes(large), 4 * map.compactable_bytes(small));
  EXPECT_TRUE(TileEviction({50.0F, 20, 0, total}).crowded_tiles(map).empty());
  // Just over: the largest goes, and what stays is within three quarters of the budget.
  ASSERT_LE(total - map.compactable_bytes(large), (total - 1) / 4 * 3);
  EXPECT_EQ(TileEviction({50.0F, 20, 0, total - 1}).crowded_tiles(map), (std::vector<TileCoord>{large}));
  // A budget nothing fits in: every tile a compaction would shrink, in coordinate order.
  EXPECT_EQ(TileEviction({50.0F, 20, 0, 1}).crowded_tiles(map), (std::vector<TileCoord>{small, large, {2, 0, 0}}));
  // A tile over compact_voxels counts as freed: with it, nothing more is needed.
  EXPECT_EQ(TileEviction({50.0F, 20, 1000, total - 1}).crowded_tiles(map), (std::vector<TileCoord>{large}));

  std::vector<MapSample> stored = map.evict(large).points;
  map.restore(large, stored);
  EXPECT_LE(map.memory_bytes(), (total - 1) / 4 * 3);
  // Compacted, it frees nothing more, so it is not chosen again while nothing is new in it.
  EXPECT_EQ(map.compactable_bytes(large), 0U);
  EXPECT_EQ(TileEviction({50.0F, 20, 0, 1}).crowded_tiles(map), (std::vector<TileCoord>{small, {2, 0, 0}}));
}

TEST(TileEviction, DistanceToATileIsZeroInsideAndToTheNearestFaceOrCornerOutside) {
  EXPECT_FLOAT_EQ(distance_to_tile({0, 0, 0}, 20.0F, {5.0F, 5.0F, 5.0F}), 0.0F);
  EXPECT_FLOAT_EQ(distance_to_tile({1, 0, 0}, 20.0F, {5.0F, 5.0F, 5.0F}), 15.0F);
  EXPECT_FLOAT_EQ(distance_to_tile({-1, 0, 0}, 20.0F, {5.0F, 5.0F, 5.0F}), 5.0F);
  EXPECT_NEAR(distance_to_tile({1, 1, 0}, 20.0F, {17.0F, 16.0F, 5.0F}), 5.0F, 1e-5F);  // (3, 4) to the corner
}

TEST(TileEviction, ATileIsColdOnlyAfterNConsecutiveKeyframesBeyondTheRadius) {
  TiledVoxelMap map({20.0F, 0.5F, 1});
  map.add(std::vector<Eigen::Vector3f>{{1.0F, 1.0F, 1.0F}, {101.0F, 1.0F, 1.0F}}, {}, 0.0);  // tiles (0,0,0), (5,0,0)
  TileEviction eviction({30.0F, 3, 0});
  const Eigen::Vector3f far_from_origin(90.0F, 1.0F, 1.0F);  // 70 m from tile 0, inside tile 4's neighbourhood
  EXPECT_TRUE(eviction.cold_tiles(map, far_from_origin).empty());
  EXPECT_TRUE(eviction.cold_tiles(map, far_from_origin).empty());
  // Back near the origin once: the count starts again.
  EXPECT_TRUE(eviction.cold_tiles(map, {10.0F, 1.0F, 1.0F}).empty());
  EXPECT_TRUE(eviction.cold_tiles(map, far_from_origin).empty());
  EXPECT_TRUE(eviction.cold_tiles(map, far_from_origin).empty());
  EXPECT_EQ(eviction.cold_tiles(map, far_from_origin), (std::vector<TileCoord>{{0, 0, 0}}));
  map.evict({0, 0, 0});
  EXPECT_TRUE(eviction.cold_tiles(map, far_from_origin).empty());  // evicted tiles are not offered again

  TileEviction never({30.0F, 0, 0});
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(never.cold_tiles(map, {1000.0F, 0.0F, 0.0F}).empty());
}

}  // namespace
}  // namespace adit::slam
