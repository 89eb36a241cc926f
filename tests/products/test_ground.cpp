#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "adit/products/ground.hpp"

namespace adit::products {
namespace {

// A 10 x 10 m floor sampled every 5 cm, a 10° ramp beside it, a 0.6 m box
// standing on the floor and a wall.
struct Scene {
  std::vector<Eigen::Vector3f> points;
  std::vector<int> kind;  // 0 floor, 1 ramp, 2 box, 3 wall
};

Scene make_scene() {
  Scene s;
  for (float x = 0; x < 10; x += 0.05F)
    for (float y = 0; y < 10; y += 0.05F) {
      s.points.emplace_back(x, y, 0.01F * std::sin(3 * x));
      s.kind.push_back(0);
    }
  for (float x = 10; x < 16; x += 0.05F)
    for (float y = 0; y < 10; y += 0.05F) {
      s.points.emplace_back(x, y, (x - 10) * std::tan(10.0F * static_cast<float>(M_PI) / 180.0F));
      s.kind.push_back(1);
    }
  for (float x = 4; x < 4.6F; x += 0.05F)
    for (float y = 4; y < 4.6F; y += 0.05F) {
      s.points.emplace_back(x, y, 0.6F);
      s.kind.push_back(2);
    }
  for (float y = 0; y < 10; y += 0.05F)
    for (float z = 0.2F; z < 3; z += 0.05F) {
      s.points.emplace_back(-0.1F, y, z);
      s.kind.push_back(3);
    }
  return s;
}

TEST(Ground, FloorAndRampAreGroundBoxAndWallAreNot) {
  const Scene s = make_scene();
  const GroundSegmentation g = segment_ground(s.points, GroundOptions{});
  std::size_t count[4] = {0, 0, 0, 0}, ground[4] = {0, 0, 0, 0};
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    ++count[s.kind[i]];
    ground[s.kind[i]] += g.is_ground[i];
  }
  EXPECT_GT(ground[0], 0.99 * count[0]);
  EXPECT_GT(ground[1], 0.95 * count[1]);
  EXPECT_EQ(ground[2], 0u);
  EXPECT_EQ(ground[3], 0u);
  EXPECT_NEAR(g.model.height_at(4.3, 4.3), 0.0, 0.05);  // under the box: the floor, not its top
  EXPECT_NEAR(g.model.height_at(14.0, 5.0), 4.0 * std::tan(10.0 * M_PI / 180.0), 0.05);
}

TEST(Ground, NoPointsNoGround) {
  const GroundSegmentation g = segment_ground({}, GroundOptions{});
  EXPECT_TRUE(g.model.empty());
  EXPECT_EQ(g.ground_points, 0u);
}

}  // namespace
}  // namespace adit::products
