#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "adit/eval/section_truth.hpp"

namespace adit::eval {
namespace {

// A drift along a direction turned 30°: 4.2 m wide, floor at z = 0, roof 4.5 m.
std::vector<Triangle> drift(const Eigen::Vector3d& along) {
  const Eigen::Vector3d across(-along.y(), along.x(), 0.0);
  std::vector<Triangle> t;
  const auto quad = [&](Eigen::Vector3d a, Eigen::Vector3d b, Eigen::Vector3d c, Eigen::Vector3d d) {
    t.push_back({a, b, c});
    t.push_back({a, c, d});
  };
  const Eigen::Vector3d s = -20 * along, e = 20 * along, l = 2.2 * across, r = -2.0 * across, up(0, 0, 4.5);
  quad(s + r, e + r, e + l, s + l);                    // floor
  quad(s + r + up, e + r + up, e + l + up, s + l + up);  // roof
  quad(s + l, e + l, e + l + up, s + l + up);          // left wall
  quad(s + r, e + r, e + r + up, s + r + up);          // right wall
  return t;
}

TEST(SectionTruth, WidthAndHeightOfATurnedDrift) {
  const Eigen::Vector3d along(std::cos(0.5236), std::sin(0.5236), 0.0);
  const std::vector<Triangle> scene = drift(along);
  const SectionTruth s = section_truth(scene, 3.0 * along + Eigen::Vector3d(0, 0, 0.65), along, 1.5);
  EXPECT_NEAR(s.width_m, 4.2, 1e-9);
  EXPECT_NEAR(s.height_m, 4.5, 1e-9);
  EXPECT_NEAR(s.floor_z, 0.0, 1e-9);
  // Cut at an angle, the width grows as 1/cos: the direction matters.
  const Eigen::Vector3d skew(std::cos(0.5236 + 0.2), std::sin(0.5236 + 0.2), 0.0);
  EXPECT_NEAR(section_truth(scene, Eigen::Vector3d(0, 0, 0.65), skew, 1.5).width_m, 4.2 / std::cos(0.2), 1e-9);
}

TEST(SectionTruth, OutsideTheSceneNothingIsMeasured) {
  const Eigen::Vector3d along(1, 0, 0);
  const SectionTruth s = section_truth(drift(along), Eigen::Vector3d(100, 0, 0.65), along, 1.5);
  EXPECT_TRUE(std::isnan(s.width_m));
  EXPECT_TRUE(std::isnan(s.height_m));
}

}  // namespace
}  // namespace adit::eval
