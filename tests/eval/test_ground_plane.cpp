// The floor under a robot's LiDAR: synthetic scans of a corridor (floor,
// walls, ceiling, a crate) seen from a tilted sensor.

#include "adit/eval/ground_plane.hpp"

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "adit/slam/roll_pitch_yaw.hpp"

namespace adit::eval {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Points of a corridor in the body frame (floor z = 0, walls y = ±1.5,
// ceiling z = 2.5, a crate's top at z = 0.4), seen by a sensor at `height`
// turned by `rpy` on the body: returned in the sensor's frame.
std::vector<Eigen::Vector3f> corridor_scan(const Eigen::Vector3d& rpy, double height, double noise, unsigned seed,
                                           bool floor = true) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> n(0.0, noise);
  Eigen::Isometry3d body_from_sensor = Eigen::Isometry3d::Identity();
  body_from_sensor.linear() = slam::rotation_from_rpy(rpy);
  body_from_sensor.translation() = Eigen::Vector3d(0.0, 0.0, height);
  const Eigen::Isometry3d sensor_from_body = body_from_sensor.inverse();
  std::vector<Eigen::Vector3f> out;
  const auto add = [&](const Eigen::Vector3d& p) { out.push_back((sensor_from_body * p).cast<float>()); };
  for (int i = 0; i < 3000; ++i) {
    const double x = 6.0 * u(rng), y = 1.5 * u(rng);
    // Without a floor (a grating, a bridge), the walls start at the sensor's level.
    const double wall_bottom = floor ? 0.0 : height;
    if (floor) add({x, y, n(rng)});
    add({x, 1.5 + n(rng), wall_bottom + (2.5 - wall_bottom) * (0.5 + 0.5 * u(rng))});
    add({x, -1.5 + n(rng), wall_bottom + (2.5 - wall_bottom) * (0.5 + 0.5 * u(rng))});
    add({x, y, 2.5 + n(rng)});
  }
  for (int i = 0; i < 150; ++i) add({2.0 + 0.3 * u(rng), 0.5 + 0.3 * u(rng), 0.3 + n(rng)});  // a crate's top
  return out;
}

TEST(GroundPlane, TheFloorUnderATiltedSensorIsFoundWithItsHeight) {
  const Eigen::Vector3d rpy(2.0 * kDeg, -4.0 * kDeg, 30.0 * kDeg);
  const auto scan = corridor_scan(rpy, 0.6, 0.01, 1);
  const auto g = find_ground(scan, Eigen::Vector3d::UnitZ(), {});
  ASSERT_TRUE(g.has_value());
  const Eigen::Vector3d up_seen = slam::rotation_from_rpy(rpy).transpose() * Eigen::Vector3d::UnitZ();
  EXPECT_LT(std::acos(std::min(1.0, g->normal.dot(up_seen))) / kDeg, 0.1);
  EXPECT_NEAR(g->height, 0.6, 0.005);
  EXPECT_GT(g->inliers, 1000u);
}

TEST(GroundPlane, ASensorHungUpsideDownFindsTheFloorAboveItsOwnZ) {
  const Eigen::Vector3d rpy(std::numbers::pi, 0.0, 0.0);
  const auto scan = corridor_scan(rpy, 1.0, 0.01, 2);
  // The turns said the body's up is the sensor's -z.
  const auto g = find_ground(scan, -Eigen::Vector3d::UnitZ(), {});
  ASSERT_TRUE(g.has_value());
  EXPECT_GT(g->normal.dot(-Eigen::Vector3d::UnitZ()), std::cos(0.1 * kDeg));
  EXPECT_NEAR(g->height, 1.0, 0.005);
}

TEST(GroundPlane, WithoutAFloorNothingIsFound) {
  const auto scan = corridor_scan(Eigen::Vector3d::Zero(), 0.6, 0.01, 3, false);
  // Walls are too steep and the ceiling is above; the crate's top is level
  // and below, but 150 points are fewer than a floor's min_inliers.
  EXPECT_FALSE(find_ground(scan, Eigen::Vector3d::UnitZ(), {}).has_value());
  EXPECT_FALSE(find_ground(std::vector<Eigen::Vector3f>{}, Eigen::Vector3d::UnitZ(), {}).has_value());
}

TEST(GroundPlane, ManyScansOnABumpyFloorAverageToTheMountingAndDropAStep) {
  // Each scan: the body tilted by the floor's bumps (±1°), the sensor at 2°/-4°.
  std::mt19937 rng(7);
  std::normal_distribution<double> bump(0.0, 0.5 * kDeg);
  const Eigen::Matrix3d mount = slam::rotation_from_rpy(Eigen::Vector3d(2.0 * kDeg, -4.0 * kDeg, 0.0));
  std::vector<GroundPlane> planes;
  for (int i = 0; i < 80; ++i) {
    GroundPlane p;
    const Eigen::Matrix3d tilt = slam::rotation_from_rpy(Eigen::Vector3d(bump(rng), bump(rng), 0.0));
    p.normal = (tilt * mount).transpose() * Eigen::Vector3d::UnitZ();
    p.height = 0.6 + 0.003 * bump(rng) / kDeg;
    planes.push_back(p);
  }
  for (int i = 0; i < 4; ++i) {  // a ramp's edge: 12° off
    GroundPlane p;
    p.normal = (slam::rotation_from_rpy(Eigen::Vector3d(0.0, 12.0 * kDeg, 0.0)) * mount).transpose() * Eigen::Vector3d::UnitZ();
    p.height = 0.9;
    planes.push_back(p);
  }
  const auto s = combine_ground(planes);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->outliers, 4u);
  EXPECT_EQ(s->scans, 80u);
  const Eigen::Vector3d up_true = mount.transpose() * Eigen::Vector3d::UnitZ();
  const double error = std::acos(std::min(1.0, s->normal.dot(up_true)));
  EXPECT_LT(error / kDeg, 0.2);
  EXPECT_LT(error, 4.0 * s->angle_sd + 1e-9) << "the standard error says how far it may be";
  EXPECT_LT(s->angle_sd / kDeg, 0.1);
  EXPECT_NEAR(s->height, 0.6, 0.005);
  EXPECT_FALSE(combine_ground({}).has_value());
}

}  // namespace
}  // namespace adit::eval
