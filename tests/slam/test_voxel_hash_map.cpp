#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <random>
#include <tuple>
#include <utility>
#include <vector>

#include "adit/slam/voxel_downsample.hpp"
#include "adit/slam/voxel_hash_map.hpp"

namespace adit::slam {
namespace {

std::vector<Eigen::Vector3f> random_points(std::size_t n, float extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-extent, extent);
  std::vector<Eigen::Vector3f> points(n);
  for (auto& p : points) p = {u(rng), u(rng), u(rng)};
  return points;
}

// The nearest point by brute force, restricted like the map to the 27 voxels around the query.
float brute_nearest_sq(const VoxelHashMap& map, const Eigen::Vector3f& q) {
  const VoxelKey c = map.key_of(q);
  float best = std::numeric_limits<float>::max();
  map.for_each_point([&](const Eigen::Vector3f& p) {
    const VoxelKey k = map.key_of(p);
    if (std::abs(k.x - c.x) <= 1 && std::abs(k.y - c.y) <= 1 && std::abs(k.z - c.z) <= 1)
      best = std::min(best, (p - q).squaredNorm());
  });
  return best;
}

TEST(VoxelHashMap, NearestFindsTheStoredPoint) {
  VoxelHashMap map(1.0F, 1024);
  const std::vector<Eigen::Vector3f> points{{0.5F, 0.5F, 0.5F}, {3.2F, -1.0F, 0.1F}};
  map.add(points);
  const MapNeighbor n = map.nearest({3.0F, -1.1F, 0.0F});
  ASSERT_TRUE(n.found);
  EXPECT_TRUE(n.point.isApprox(points[1]));
  EXPECT_NEAR(n.distance_sq, 0.04F + 0.01F + 0.01F, 1e-5F);
  EXPECT_FALSE(map.nearest({10.0F, 10.0F, 10.0F}).found);
}

TEST(VoxelHashMap, KeepsAtMostTheVoxelCapacityAndCountsTheRest) {
  VoxelHashMap map(1.0F, 64);
  std::vector<Eigen::Vector3f> same_voxel(VoxelHashMap::kMaxPointsPerVoxel + 5, Eigen::Vector3f(0.1F, 0.2F, 0.3F));
  map.add(same_voxel);
  EXPECT_EQ(map.voxel_count(), 1U);
  EXPECT_EQ(map.point_count(), static_cast<std::size_t>(VoxelHashMap::kMaxPointsPerVoxel));
  EXPECT_EQ(map.dropped_points(), 5U);
}

// A VLP-16 ring crosses a 0.5 m voxel as a row of points, and the next scans'
// rings cross it close to the same row. First come (no spacing), the first
// rows fill the voxel and a later ring at another height is refused: the map
// keeps the sampling of the scans that first saw the surface. With a minimum
// spacing a row takes a few points and the later ring enters too.
TEST(VoxelHashMap, AMinimumSpacingLetsALaterRingIntoAVoxelTheFirstRowsWouldFill) {
  std::vector<Eigen::Vector3f> first_rows;  // three scans' rings, 1 cm apart in height, 2 cm along
  for (int row = 0; row < 3; ++row)
    for (int i = 0; i < 24; ++i) first_rows.emplace_back(0.01F + 0.02F * static_cast<float>(i), 0.25F, 0.1F + 0.01F * static_cast<float>(row));
  std::vector<Eigen::Vector3f> later_ring;
  for (int i = 0; i < 24; ++i) later_ring.emplace_back(0.01F + 0.02F * static_cast<float>(i), 0.25F, 0.4F);

  VoxelHashMap first_come(0.5F, 64);
  EXPECT_FLOAT_EQ(first_come.min_point_spacing(), 0.0F);
  first_come.add(first_rows);
  first_come.add(later_ring);
  EXPECT_EQ(first_come.point_count(), static_cast<std::size_t>(VoxelHashMap::kMaxPointsPerVoxel));
  first_come.for_each_point([](const Eigen::Vector3f& p) { EXPECT_LT(p.z(), 0.15F); });  // nothing of the later ring

  const float spacing = 0.5F / std::sqrt(static_cast<float>(VoxelHashMap::kMaxPointsPerVoxel));  // KISS-ICP's
  VoxelHashMap spaced(0.5F, 64, spacing);
  spaced.add(first_rows);
  const std::size_t after_rows = spaced.point_count();
  EXPECT_GE(after_rows, 4U);   // the row, every ~0.12 m of its 0.48 m
  EXPECT_LE(after_rows, 5U);   // the two rows 1-2 cm above it add nothing
  spaced.add(later_ring);
  EXPECT_EQ(spaced.point_count(), 2 * after_rows);  // the later ring enters, as evenly
  EXPECT_EQ(spaced.voxel_count(), 1U);
  EXPECT_EQ(spaced.dropped_points(), first_rows.size() + later_ring.size() - spaced.point_count());
  std::vector<Eigen::Vector3f> kept;
  spaced.for_each_point([&](const Eigen::Vector3f& p) { kept.push_back(p); });
  for (std::size_t a = 0; a < kept.size(); ++a)
    for (std::size_t b = a + 1; b < kept.size(); ++b) EXPECT_GE((kept[a] - kept[b]).norm(), spacing);
}

TEST(VoxelHashMap, RefusesNewVoxelsBeyondThreeQuartersOfTheTable) {
  VoxelHashMap map(1.0F, 16);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 20; ++i) points.emplace_back(static_cast<float>(i) + 0.5F, 0.5F, 0.5F);
  map.add(points);
  EXPECT_EQ(map.voxel_count(), 12U);
  EXPECT_EQ(map.dropped_points(), 8U);
}

TEST(VoxelHashMap, NearestPlaneFitsTheNeighboursAndRefusesLinesAndClutter) {
  VoxelHashMap map(0.5F, 256);
  std::vector<Eigen::Vector3f> floor;  // z = 0.2, spread over several voxels
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) floor.emplace_back(0.1F * static_cast<float>(i), 0.1F * static_cast<float>(j), 0.2F);
  map.add(floor);
  const MapPlane plane = map.nearest_plane({0.25F, 0.25F, 0.3F}, 5);
  ASSERT_TRUE(plane.found);
  EXPECT_NEAR(std::abs(plane.normal.z()), 1.0F, 1e-4F);
  EXPECT_NEAR(plane.point.z(), 0.2F, 1e-5F);

  // One ring of a spinning LiDAR: points along a line have no plane.
  VoxelHashMap ring(0.5F, 256);
  std::vector<Eigen::Vector3f> line;
  for (int i = 0; i < 10; ++i) line.emplace_back(5.0F + 0.05F * static_cast<float>(i), 1.0F, 0.0F);
  ring.add(line);
  EXPECT_FALSE(ring.nearest_plane({5.2F, 1.05F, 0.0F}, 5).found);

  // Clutter: neighbours spread in every direction (an octahedron's corners).
  VoxelHashMap clutter(0.5F, 256);
  const Eigen::Vector3f c(5.25F, 5.25F, 5.25F);
  std::vector<Eigen::Vector3f> corners;
  for (int axis = 0; axis < 3; ++axis)
    for (const float sign : {-0.1F, 0.1F}) corners.push_back(c + sign * Eigen::Vector3f::Unit(axis));
  clutter.add(corners);
  EXPECT_FALSE(clutter.nearest_plane(c, 5).found);

  // Fewer neighbours within a voxel edge than asked for: none.
  EXPECT_FALSE(map.nearest_plane({3.0F, 3.0F, 3.0F}, 5).found);
}

// The plane search visits the 27 voxels nearest-first and skips those
// beyond its bound: it must still use exactly the k map points nearest the
// query within one voxel edge. A gently tilted, rough floor at random
// offsets, against brute force (the plane's point is those points' mean).
TEST(VoxelHashMap, NearestPlaneUsesExactlyTheKNearestPointsWithinAVoxelEdge) {
  constexpr float kVoxel = 0.5F;
  constexpr int kNeighbors = 10;
  VoxelHashMap map(kVoxel, 4096);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-2.0F, 2.0F);
  std::uniform_real_distribution<float> noise(-0.01F, 0.01F);
  std::vector<Eigen::Vector3f> points;
  // Sparse enough (about 40 per m²) that the tenth neighbour lies 0.3 m away
  // and often in a neighbouring voxel, on the far side as well.
  for (int i = 0; i < 600; ++i) {
    const float x = u(rng);
    const float y = u(rng);
    points.emplace_back(x, y, 0.1F * x - 0.05F * y + noise(rng));
  }
  map.add(points);
  int checked = 0;
  for (int q = 0; q < 300; ++q) {
    const float x = 0.8F * u(rng);
    const float y = 0.8F * u(rng);
    const Eigen::Vector3f query(x, y, 0.1F * x - 0.05F * y + 5.0F * noise(rng));
    std::vector<std::pair<float, Eigen::Vector3f>> near;
    map.for_each_point([&](const Eigen::Vector3f& p) {
      const float d = (p - query).squaredNorm();
      if (d < kVoxel * kVoxel) near.emplace_back(d, p);
    });
    std::sort(near.begin(), near.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    const MapPlane plane = map.nearest_plane(query, kNeighbors);
    ASSERT_EQ(plane.found, near.size() >= kNeighbors) << "query " << q;
    if (!plane.found) continue;
    Eigen::Vector3f mean = Eigen::Vector3f::Zero();
    for (int i = 0; i < kNeighbors; ++i) mean += near[static_cast<std::size_t>(i)].second / kNeighbors;
    EXPECT_LT((plane.point - mean).norm(), 1e-5F) << "query " << q;
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

TEST(VoxelKey, FloorToIntMatchesStdFloor) {
  for (const float x : {-2.0F, -1.5F, -1.0F, -0.9999999F, -1e-30F, -0.0F, 0.0F, 1e-30F, 0.5F, 0.9999999F, 1.0F,
                        123456.7F, -123456.7F, 8388607.5F, -8388607.5F, 1e9F, -1e9F})
    EXPECT_EQ(floor_to_int(x), static_cast<std::int32_t>(std::floor(x))) << x;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1000.0F, 1000.0F);
  for (int i = 0; i < 100000; ++i) {
    const float x = u(rng);
    ASSERT_EQ(floor_to_int(x), static_cast<std::int32_t>(std::floor(x))) << x;
  }
}

// remove_far under heavy hash collisions (a small, nearly full table): every
// far voxel goes, every near one stays findable, and nearest() agrees with
// brute force afterwards. This exercises the backward-shift deletion.
TEST(VoxelHashMap, RemoveFarKeepsEveryNearVoxelFindable) {
  VoxelHashMap map(0.5F, 4096);
  const auto points = random_points(20000, 12.0F, 7);
  map.add(points);
  const Eigen::Vector3f origin(2.0F, -1.0F, 0.5F);
  map.remove_far(origin, 8.0F);
  std::size_t remaining = 0;
  map.for_each_point([&](const Eigen::Vector3f&) { ++remaining; });
  EXPECT_EQ(remaining, map.point_count());
  EXPECT_GT(map.voxel_count(), 100U);
  for (const auto& q : random_points(500, 12.0F, 11)) {
    const MapNeighbor n = map.nearest(q);
    const float expected = brute_nearest_sq(map, q);
    if (expected == std::numeric_limits<float>::max()) {
      EXPECT_FALSE(n.found);
    } else {
      ASSERT_TRUE(n.found);
      EXPECT_FLOAT_EQ(n.distance_sq, expected);
    }
  }
  // Nothing left is far: each remaining voxel's first point was within 8 m,
  // so every point is within 8 m plus a voxel diagonal.
  map.for_each_point([&](const Eigen::Vector3f& p) { EXPECT_LE((p - origin).norm(), 8.0F + 0.87F); });
}

// remove_far decides most voxels from their box alone: it must still remove
// exactly the voxels whose first point is beyond the distance, also for the
// voxels the sphere cuts through (brute force on the insertion order).
TEST(VoxelHashMap, RemoveFarRemovesExactlyTheVoxelsWhoseFirstPointIsFar) {
  VoxelHashMap map(0.5F, 1 << 16);
  const auto points = random_points(30000, 9.0F, 3);
  map.add(points);
  ASSERT_EQ(map.dropped_points(), 0U);
  const Eigen::Vector3f origin(0.37F, -0.21F, 0.13F);
  const float max_distance = 6.1F;
  std::map<std::tuple<int, int, int>, Eigen::Vector3f> first;
  for (const auto& p : points) {
    const VoxelKey k = map.key_of(p);
    first.try_emplace({k.x, k.y, k.z}, p);
  }
  std::size_t kept_expected = 0;
  std::size_t straddling = 0;
  for (const auto& p : points) {
    const VoxelKey k = map.key_of(p);
    const Eigen::Vector3f& f = first.at({k.x, k.y, k.z});
    if ((f - origin).norm() <= max_distance) ++kept_expected;
    const Eigen::Vector3f centre =
        (Eigen::Vector3i(k.x, k.y, k.z).cast<float>() + Eigen::Vector3f::Constant(0.5F)) * 0.5F;
    if (std::abs((centre - origin).norm() - max_distance) < 0.43F) ++straddling;
  }
  ASSERT_GT(straddling, 1000U);  // the boundary case is exercised
  map.remove_far(origin, max_distance);
  EXPECT_EQ(map.point_count(), kept_expected);
  map.for_each_point([&](const Eigen::Vector3f& p) {
    const VoxelKey k = map.key_of(p);
    EXPECT_LE((first.at({k.x, k.y, k.z}) - origin).norm(), max_distance);
  });
}

TEST(VoxelHashMap, ClearEmptiesTheMap) {
  VoxelHashMap map(1.0F, 256);
  map.add(random_points(100, 5.0F, 1));
  map.clear();
  EXPECT_TRUE(map.empty());
  EXPECT_EQ(map.point_count(), 0U);
  EXPECT_FALSE(map.nearest({0.0F, 0.0F, 0.0F}).found);
}

TEST(VoxelDownsampler, KeepsTheFirstPointOfEachVoxelInInputOrder) {
  VoxelDownsampler downsampler(100);
  const std::vector<Eigen::Vector3f> in{{0.1F, 0.1F, 0.1F}, {0.2F, 0.2F, 0.2F}, {1.5F, 0.1F, 0.1F},
                                        {-0.1F, 0.1F, 0.1F}, {1.9F, 0.9F, 0.9F}};
  std::vector<Eigen::Vector3f> out;
  out.reserve(100);
  ASSERT_EQ(downsampler.downsample(in, 1.0F, out), 3U);
  EXPECT_EQ(out[0], in[0]);
  EXPECT_EQ(out[1], in[2]);
  EXPECT_EQ(out[2], in[3]);  // x = -0.1 is voxel -1, not 0
}

TEST(VoxelDownsampler, CallsAreIndependentAndBoundedByMaxPoints) {
  VoxelDownsampler downsampler(10);
  std::vector<Eigen::Vector3f> out;
  out.reserve(10);
  const auto points = random_points(1000, 50.0F, 5);
  EXPECT_EQ(downsampler.downsample(points, 0.1F, out), 10U);
  const std::vector<Eigen::Vector3f> one{{0.0F, 0.0F, 0.0F}};
  EXPECT_EQ(downsampler.downsample(one, 0.1F, out), 1U);
  EXPECT_EQ(downsampler.downsample(one, 0.1F, out), 1U);  // not remembered from the previous call
}

// Against brute force (first point of each voxel, in input order) over calls
// of very different sizes, so that each call uses a different part of the
// table and must not see the marks of earlier calls; with runs of points in
// one voxel, which skip the lookup.
TEST(VoxelDownsampler, MatchesBruteForceAcrossCallsOfDifferentSizes) {
  VoxelDownsampler downsampler(50000);
  std::vector<Eigen::Vector3f> out;
  out.reserve(50000);
  for (const std::size_t n : {40000U, 30U, 25000U, 1U, 40000U}) {
    auto points = random_points(n, 20.0F, static_cast<unsigned>(n));
    for (std::size_t i = 1; i < points.size(); i += 3) points[i] = points[i - 1] + Eigen::Vector3f::Constant(0.01F);
    std::map<std::tuple<int, int, int>, bool> seen;
    std::vector<Eigen::Vector3f> expected;
    for (const auto& p : points) {
      const VoxelKey k = voxel_key(p, 1.0F / 0.3F);
      if (seen.try_emplace({k.x, k.y, k.z}, true).second) expected.push_back(p);
    }
    ASSERT_EQ(downsampler.downsample(points, 0.3F, out), expected.size()) << n;
    EXPECT_TRUE(std::equal(out.begin(), out.end(), expected.begin())) << n;
  }
}

}  // namespace
}  // namespace adit::slam
