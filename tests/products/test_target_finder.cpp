#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "adit/products/target_finder.hpp"

namespace adit::products {
namespace {

// A wall at y = 2 (intensity 40) with two bright 0.15 m discs on it, and one
// large bright patch (a reflective sign, 1.5 m wide) that is no target.
TEST(TargetFinder, DiscsAreFoundAtTheirCentresLargeBrightPatchesAreNot) {
  std::vector<Eigen::Vector3f> points;
  std::vector<float> intensity;
  const Eigen::Vector2f discs[2] = {{3.0125F, 1.5125F}, {12.0125F, 1.2125F}};  // on the points' lattice
  for (int i = 0; i < 400; ++i)
    for (int j = 0; j < 60; ++j) {
      const float x = static_cast<float>(0.0125 + 0.05 * i), z = static_cast<float>(0.0125 + 0.05 * j);
      points.emplace_back(x, 2.0F, z);
      bool bright = (x > 16 && x < 17.5F && z > 1 && z < 2);
      for (const Eigen::Vector2f& d : discs) bright |= std::hypot(x - d.x(), z - d.y()) < 0.16F;  // off the lattice's rings
      intensity.push_back(bright ? 220.0F : 40.0F);
    }
  slam::Trajectory path;
  for (int k = 0; k <= 20; ++k) {
    slam::Pose p = slam::Pose::Identity();
    p.translation() = Eigen::Vector3d(k, 0, 0.5);
    path.push_back(k, p);
  }
  const std::vector<FoundTarget> found = find_targets(points, intensity, path, TargetOptions{});
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].id, 1);  // in order along the path
  EXPECT_NEAR(found[0].centre.x(), 3.0125, 1e-4);
  EXPECT_NEAR(found[0].centre.z(), 1.5125, 1e-4);
  EXPECT_NEAR(found[1].centre.x(), 12.0125, 1e-4);
  EXPECT_GT(found[0].sigma_m, 0.0);
  EXPECT_LT(found[0].sigma_m, 0.01);
  // Out of reach of the path: not looked at.
  TargetOptions near;
  near.max_path_distance_m = 1.0;
  EXPECT_TRUE(find_targets(points, intensity, path, near).empty());
}

}  // namespace
}  // namespace adit::products
