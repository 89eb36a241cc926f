// VoxelBrickSet: holds exactly the voxels inserted, on both sides of zero,
// after growing far past its first size; its brick reader agrees with it.
#include <random>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "adit/products/voxel_brick_set.hpp"

namespace adit::products {
namespace {

using Key = std::tuple<std::int64_t, std::int64_t, std::int64_t>;

TEST(VoxelBrickSet, HoldsExactlyTheVoxelsInsertedAfterGrowing) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::int64_t> coord(-40, 40);
  VoxelBrickSet set(4);  // far too small: it must grow
  std::set<Key> truth;
  for (int i = 0; i < 20000; ++i) {
    const VoxelIndex v{coord(rng), coord(rng), coord(rng) / 8};
    set.insert(v);
    truth.emplace(v.x, v.y, v.z);
  }
  VoxelBrickSet::BrickReader reader(set);
  std::size_t held = 0;
  for (std::int64_t x = -42; x <= 42; ++x)
    for (std::int64_t y = -42; y <= 42; ++y)
      for (std::int64_t z = -7; z <= 7; ++z) {
        const bool expected = truth.count({x, y, z}) > 0;
        ASSERT_EQ(set.contains({x, y, z}), expected) << x << " " << y << " " << z;
        ASSERT_EQ(reader.contains({x, y, z}), expected) << x << " " << y << " " << z;
        held += expected;
      }
  EXPECT_EQ(held, truth.size());
}

TEST(VoxelBrickSet, NeighboursAcrossZeroAreDistinct) {
  VoxelBrickSet set(16);
  set.insert({-1, 0, 0});
  EXPECT_TRUE(set.contains({-1, 0, 0}));
  for (const VoxelIndex& v : {VoxelIndex{0, 0, 0}, VoxelIndex{-2, 0, 0}, VoxelIndex{-1, -1, 0}, VoxelIndex{-1, 0, -1},
                              VoxelIndex{-5, 0, 0}, VoxelIndex{3, 0, 0}})
    EXPECT_FALSE(set.contains(v)) << v.x << " " << v.y << " " << v.z;
  EXPECT_EQ(set.bricks(), 1u);
  // Far apart, in one brick coordinate's 21 bits: distinct bricks.
  set.insert({4'000'000, -4'000'000, 12});
  EXPECT_TRUE(set.contains({4'000'000, -4'000'000, 12}));
  EXPECT_FALSE(set.contains({4'000'001, -4'000'000, 12}));
  EXPECT_EQ(set.bricks(), 2u);
}

}  // namespace
}  // namespace adit::products
