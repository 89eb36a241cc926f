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

}  // namespace
}  // namespace adit::slam
