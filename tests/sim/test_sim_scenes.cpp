// Scenes: the building's "as designed" model agrees with the built floor
// except where it should not (furniture, one moved partition); the mine has
// its loop, and its walls are rough at the centimetre-decimetre scale.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "adit/sim/ray_caster.hpp"
#include "adit/sim/scene.hpp"

namespace adit::sim {
namespace {

TEST(SimScenes, BuildingDesignDiffersFromTheBuiltFloorInSmallWays) {
  const Scene scene = make_building(5);
  ASSERT_FALSE(scene.design.triangles.empty());
  const RayCaster built(scene.mesh);
  const RayCaster designed(scene.design);
  std::size_t rays = 0, differ = 0, missing = 0;
  for (std::size_t i = 0; i < scene.route.points.size(); i += 40) {
    for (int k = 0; k < 64; ++k) {
      const double a = 2 * std::numbers::pi * k / 64;
      const Eigen::Vector3f origin(static_cast<float>(scene.route.points[i].x()),
                                   static_cast<float>(scene.route.points[i].y()), 0.5F);
      const Eigen::Vector3f dir(static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), -0.05F);
      const Hit b = built.intersect(origin, dir.normalized(), 0.0F, 100.0F);
      const Hit d = designed.intersect(origin, dir.normalized(), 0.0F, 100.0F);
      ++rays;
      if (!b.valid() || !d.valid()) {
        ++missing;  // a closed floor: every ray ends on a surface
        continue;
      }
      if (std::abs(b.distance - d.distance) > 0.05F) ++differ;
    }
  }
  EXPECT_EQ(missing, 0u);
  const double fraction = static_cast<double>(differ) / static_cast<double>(rays);
  EXPECT_GT(fraction, 0.005) << "the built floor should not be the design";
  EXPECT_LT(fraction, 0.3) << "the design should still describe most of the floor";
}

TEST(SimScenes, MineHasALoopAndRoughWalls) {
  const Scene scene = make_mine(11);
  EXPECT_TRUE(scene.route.closed);
  EXPECT_GT(scene.route.length(), 100.0);
  EXPECT_LT(scene.route.length(), 500.0);
  // Wall roughness: across the middle half of the first drift (no junction there),
  // sampled every 10 cm, the width is the drawn one give or take cm to dm.
  const Drift& drift = scene.plan.drifts[0];
  const Eigen::Vector2d axis = (drift.b - drift.a).normalized();
  const Eigen::Vector3f left(static_cast<float>(-axis.y()), static_cast<float>(axis.x()), 0.0F);
  const RayCaster caster(scene.mesh);
  double min_width = 1e9, max_width = 0;
  const double length = (drift.b - drift.a).norm();
  for (double s = 0.25 * length; s < 0.75 * length; s += 0.1) {
    const Eigen::Vector2d p = drift.a + axis * s;
    const Eigen::Vector3f origin(static_cast<float>(p.x()), static_cast<float>(p.y()), 1.5F);
    const Hit l = caster.intersect(origin, left, 0.0F, 20.0F);
    const Hit r = caster.intersect(origin, -left, 0.0F, 20.0F);
    ASSERT_TRUE(l.valid() && r.valid());
    const double w = l.distance + r.distance;
    min_width = std::min(min_width, w);
    max_width = std::max(max_width, w);
  }
  EXPECT_GE(drift.width_m, 3.5);
  EXPECT_LE(drift.width_m, 5.0);
  EXPECT_GT(min_width, drift.width_m - 0.35);
  EXPECT_LT(max_width, drift.width_m + 0.35);
  EXPECT_GT(max_width - min_width, 0.05);
}

}  // namespace
}  // namespace adit::sim
