// The live 2D grid: obstacles in the band, free space by rays, only changed
// patches reported, people who walk away cleared.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "adit/slam/live_grid.hpp"

namespace adit::slam {
namespace {

// The walls stand mid-cell (5 cm cells), so rounding cannot move them to the next.
constexpr float kHalfWidth = 2.025F;

// A straight drift along x: walls at y = ±half_width from x = -length to
// +length, the floor at z = floor_z, sampled as a spinning LiDAR at the origin
// would (rays every 0.2° in azimuth and 2° in elevation, ±15°), no ceiling.
std::vector<Eigen::Vector3f> drift_scan(const Eigen::Vector3f& sensor, float half_width, float floor_z,
                                        float length) {
  std::vector<Eigen::Vector3f> points;
  for (float el_deg = -15.0F; el_deg <= 15.0F; el_deg += 2.0F) {
    const float el = el_deg * std::numbers::pi_v<float> / 180.0F;
    for (float az_deg = 0.0F; az_deg < 360.0F; az_deg += 0.2F) {
      const float az = az_deg * std::numbers::pi_v<float> / 180.0F;
      const Eigen::Vector3f dir(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      float t = std::numeric_limits<float>::infinity();
      if (dir.y() != 0) t = std::min(t, ((dir.y() > 0 ? half_width : -half_width) - sensor.y()) / dir.y());
      if (dir.z() < 0) t = std::min(t, (floor_z - sensor.z()) / dir.z());
      const Eigen::Vector3f p = sensor + t * dir;
      if (std::isfinite(t) && std::abs(p.x()) <= length) points.push_back(p);
    }
  }
  return points;
}

// The value of the cell holding map position (x, y).
std::int8_t value_at(const LiveGrid& grid, float x, float y) {
  const int n = grid.config().patch_cells;
  const auto i = static_cast<int>(std::floor(x / grid.config().resolution_m));
  const auto j = static_cast<int>(std::floor(y / grid.config().resolution_m));
  const GridPatchCoord patch{static_cast<int>(std::floor(static_cast<float>(i) / n)),
                             static_cast<int>(std::floor(static_cast<float>(j) / n))};
  std::vector<std::int8_t> cells(static_cast<std::size_t>(n) * n);
  grid.read(patch, cells);
  return cells[static_cast<std::size_t>((j - patch.y * n) * n + (i - patch.x * n))];
}

TEST(LiveGrid, ADriftsWallsAreOccupiedItsFloorFreeAndBeyondUnknown) {
  LiveGrid grid(LiveGridConfig{});
  const Eigen::Vector3f sensor(0.3F, 0.2F, 1.0F);
  for (int k = 0; k < 5; ++k) grid.insert(sensor, drift_scan(sensor, kHalfWidth, 0.0F, 30.0F));
  // Within 4 m the beams fall on the walls closer than a cell; farther they
  // graze them, and the rays to the next beam's point pass the cells between.
  for (float x = -4.0F; x <= 4.0F; x += 0.5F) {
    EXPECT_EQ(value_at(grid, x, kHalfWidth), kGridOccupied) << "wall at x " << x;
    EXPECT_EQ(value_at(grid, x, -kHalfWidth), kGridOccupied) << "wall at x " << x;
    EXPECT_EQ(value_at(grid, x, 2.5F), kGridUnknown) << "behind the wall at x " << x;
  }
  // The walls' band hits end the rays across; along the drift the floor's
  // rays say the band was free up to 0.5/1.0 of their reach.
  for (float x = -4.0F; x <= 4.0F; x += 0.5F)
    for (float y = -1.5F; y <= 1.5F; y += 0.5F) EXPECT_EQ(value_at(grid, x, y), kGridFree) << x << ", " << y;
  EXPECT_EQ(grid.counts().scans, 5U);
  EXPECT_GT(grid.counts().hit_updates, 0U);
}

TEST(LiveGrid, OnlyPatchesWhoseValuesChangedAreReportedEachWithANewVersion) {
  LiveGrid grid(LiveGridConfig{});
  const Eigen::Vector3f sensor(0.0F, 0.0F, 1.0F);
  const std::vector<Eigen::Vector3f> scan = drift_scan(sensor, kHalfWidth, 0.0F, 30.0F);
  grid.insert(sensor, scan);
  const std::vector<GridPatchCoord> first = grid.take_changed();
  ASSERT_FALSE(first.empty());
  const std::vector<GridPatchCoord> all = grid.patch_coords();
  for (const GridPatchCoord& c : first) {
    EXPECT_EQ(grid.version(c), 1);
    EXPECT_TRUE(std::find(all.begin(), all.end(), c) != all.end());
  }
  // Repeated, the scan turns more cells free (four misses make a cell free),
  // then nothing changes: the log-odds are clamped.
  for (int k = 0; k < 10; ++k) grid.insert(sensor, scan);
  EXPECT_FALSE(grid.take_changed().empty());
  grid.insert(sensor, scan);
  EXPECT_TRUE(grid.take_changed().empty());
  EXPECT_TRUE(grid.take_changed().empty());
}

TEST(LiveGrid, APersonWhoWalksAwayIsClearedAndAWallSeenThroughAPersonStays) {
  LiveGridConfig config;
  LiveGrid grid(config);
  const Eigen::Vector3f sensor(0.0F, 0.0F, 1.0F);
  std::vector<Eigen::Vector3f> with_person = drift_scan(sensor, kHalfWidth, 0.0F, 30.0F);
  // A person at x = 3: a column of points at heights 0.6-1.4 (in the band).
  for (float z = 0.6F; z <= 1.4F; z += 0.1F) with_person.emplace_back(3.02F, 0.02F, z);
  for (int k = 0; k < 3; ++k) grid.insert(sensor, with_person);
  EXPECT_EQ(value_at(grid, 3.02F, 0.02F), kGridOccupied);
  // The same cell, passed by a ray to a wall beyond in the same scan, stays hit.
  const std::vector<Eigen::Vector3f> without = drift_scan(sensor, kHalfWidth, 0.0F, 30.0F);
  std::vector<Eigen::Vector3f> far_wall = without;
  far_wall.emplace_back(6.02F, 0.04F, 1.0F);
  far_wall.emplace_back(3.02F, 0.02F, 1.0F);
  grid.insert(sensor, far_wall);
  EXPECT_EQ(value_at(grid, 3.02F, 0.02F), kGridOccupied);
  // Gone: the floor's rays pass where it stood, and after enough scans it is free.
  for (int k = 0; k < 20; ++k) grid.insert(sensor, without);
  EXPECT_EQ(value_at(grid, 3.02F, 0.02F), kGridFree);
}

TEST(LiveGrid, AnOccupiedCellPassedOnceStaysOccupiedButClearsWhenPassedOften) {
  LiveGrid grid(LiveGridConfig{});
  const Eigen::Vector3f sensor(0.0F, 0.0F, 1.0F);
  const Eigen::Vector3f wall(4.025F, 1.025F, 1.0F);
  grid.insert(sensor, std::vector<Eigen::Vector3f>{wall});
  EXPECT_EQ(value_at(grid, 4.025F, 1.025F), kGridOccupied);
  // A ray to a point beyond, on the same line, passes the cell: a grazing ray's miss.
  const std::vector<Eigen::Vector3f> beyond{sensor + 2.0F * (wall - sensor)};
  grid.insert(sensor, beyond);
  EXPECT_EQ(value_at(grid, 4.025F, 1.025F), kGridOccupied);  // a whole miss would leave it unknown
  for (int k = 0; k < 6; ++k) grid.insert(sensor, beyond);
  EXPECT_EQ(value_at(grid, 4.025F, 1.025F), kGridFree);
}

TEST(LiveGrid, PatchesOnEverySideOfTheOriginHoldTheirCells) {
  LiveGridConfig config;
  config.patch_cells = 16;  // 0.8 m patches: the drift spans many, negative ones too
  LiveGrid grid(config);
  const Eigen::Vector3f sensor(-0.01F, -0.01F, 1.0F);
  for (int k = 0; k < 5; ++k) grid.insert(sensor, drift_scan(sensor, kHalfWidth, 0.0F, 30.0F));
  EXPECT_EQ(value_at(grid, -5.0F, -kHalfWidth), kGridOccupied);
  EXPECT_EQ(value_at(grid, 5.0F, kHalfWidth), kGridOccupied);
  EXPECT_EQ(value_at(grid, -3.0F, -0.5F), kGridFree);
  EXPECT_EQ(value_at(grid, -0.01F, -0.01F), kGridFree);
  bool negative = false;
  for (const GridPatchCoord& c : grid.patch_coords()) negative = negative || (c.x < 0 && c.y < 0);
  EXPECT_TRUE(negative);
  EXPECT_EQ(value_at(grid, 40.0F, 40.0F), kGridUnknown);  // never seen: no patch, unknown
}

TEST(LiveGrid, AFarFloorThatATiltLiftsIntoTheBandIsNoObstacle) {
  // The map is tilted by 1.5° (an attitude error): the floor 1 m below the
  // sensor rises into the band (0.5 m below) beyond ~19 m.
  const Eigen::Vector3f sensor(0.0F, 0.0F, 1.0F);
  const float slope = std::tan(1.5F * std::numbers::pi_v<float> / 180.0F);
  std::vector<Eigen::Vector3f> floor;
  for (int k = 0; k < 660; ++k) {  // mid-cell, every cell from 2 m to 35 m
    const float x = 2.025F + 0.05F * static_cast<float>(k);
    floor.emplace_back(x, 0.01F, x * slope);
  }
  LiveGridConfig tolerant;
  tolerant.tilt_tolerance_deg = 2.0F;
  LiveGridConfig strict = tolerant;
  strict.tilt_tolerance_deg = 0.0F;
  LiveGrid with_tolerance(tolerant);
  LiveGrid without(strict);
  with_tolerance.insert(sensor, floor);
  without.insert(sensor, floor);
  EXPECT_EQ(with_tolerance.counts().hit_updates, 0U);
  EXPECT_EQ(value_at(with_tolerance, 25.025F, 0.01F), kGridUnknown);
  EXPECT_GT(without.counts().hit_updates, 0U);
  EXPECT_EQ(value_at(without, 25.025F, 0.01F), kGridOccupied);
  // A wall 10.5 m away stays an obstacle: within 0.5 - 10.5·tan 2° = 0.13 m of the sensor's height.
  with_tolerance.insert(sensor, std::vector<Eigen::Vector3f>{{10.025F, 3.025F, 1.1F}});
  EXPECT_EQ(value_at(with_tolerance, 10.025F, 3.025F), kGridOccupied);
}

TEST(LiveGrid, PointsOutOfTheBandOrRangeOrNotFiniteMakeNoObstacle) {
  LiveGridConfig config;
  config.max_range_m = 10.0F;
  LiveGrid grid(config);
  const Eigen::Vector3f sensor(0.0F, 0.0F, 1.0F);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<Eigen::Vector3f> points{{2.0F, 0.0F, 2.0F},    // above the band
                                            {-2.0F, 0.0F, 0.2F},   // below it
                                            {0.0F, 15.0F, 1.0F},   // beyond the range
                                            {nan, 1.0F, 1.0F},
                                            {1.0F, nan, 1.0F}};
  grid.insert(sensor, points);
  EXPECT_EQ(grid.counts().hit_updates, 0U);
  EXPECT_EQ(value_at(grid, 2.0F, 0.0F), kGridUnknown);
  EXPECT_EQ(value_at(grid, 0.0F, 15.0F), kGridUnknown);
}

}  // namespace
}  // namespace adit::slam

namespace adit::slam {
namespace {

// Down a 160 m drift and back (max range 20 m): the patches the sensor
// leaves freeze, those it comes back to thaw, and the grid reads, reports and
// versions exactly as one that never froze.
TEST(LiveGrid, PatchesBeyondTheRaysFreezeAndThawExactlyAsTheyWere) {
  LiveGridConfig config;
  config.max_range_m = 20.0F;
  LiveGridConfig whole = config;
  whole.freeze_far_patches = false;
  LiveGrid grid(config);
  LiveGrid reference(whole);
  std::size_t most_frozen = 0;
  for (int k = 0; k <= 160; ++k) {
    const float x = k <= 80 ? 2.0F * static_cast<float>(k) : 2.0F * static_cast<float>(160 - k);
    const Eigen::Vector3f sensor(x, 0.3F, 0.0F);
    const auto scan = drift_scan(sensor, kHalfWidth, -1.0F, 200.0F);
    grid.insert(sensor, scan);
    reference.insert(sensor, scan);
    ASSERT_EQ(grid.take_changed(), reference.take_changed()) << "scan " << k;
    most_frozen = std::max(most_frozen, grid.frozen_count());
  }
  EXPECT_GT(most_frozen, grid.patch_count() / 2) << "at the drift's far end most patches lie beyond 20 m";
  EXPECT_GT(grid.counts().thaws, 0U) << "and the way back reached them again";
  EXPECT_GT(grid.frozen_count(), 0U) << "the far end's patches stay frozen";
  ASSERT_EQ(grid.patch_coords(), reference.patch_coords());
  const auto cells = static_cast<std::size_t>(config.patch_cells) * static_cast<std::size_t>(config.patch_cells);
  std::vector<std::int8_t> a(cells), b(cells);
  for (const GridPatchCoord c : grid.patch_coords()) {
    grid.read(c, a);
    reference.read(c, b);
    ASSERT_EQ(a, b) << c.x << ", " << c.y;
    EXPECT_EQ(grid.version(c), reference.version(c));
  }
  EXPECT_LT(grid.memory_bytes(), reference.memory_bytes() / 2) << grid.frozen_count() << " of " << grid.patch_count() << " frozen";
}

}  // namespace
}  // namespace adit::slam
