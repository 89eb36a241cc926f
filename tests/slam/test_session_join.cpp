// Joining sessions: a second session whose path runs out of the stored map's
// area is placed in it by the places where they overlap; a session elsewhere,
// or one that overlaps at a single place, is refused with the reason.
#include <gtest/gtest.h>

#include <numbers>
#include <vector>

#include "adit/slam/prior_map.hpp"
#include "adit/slam/session_join.hpp"
#include "plan_scene.hpp"

namespace adit::slam {
namespace {

using namespace plan_scene;

std::vector<Eigen::Vector3f> moved(const std::vector<Eigen::Vector3f>& points, const Eigen::Isometry3d& to_from) {
  std::vector<Eigen::Vector3f> out;
  const Eigen::Isometry3f t = to_from.cast<float>();
  for (const auto& p : points) out.push_back(t * p);
  return out;
}

// A path along y = 11.5 (through the door), body 0.2 m above the floor, in the frame `new_from_world`.
Trajectory path(double x0, double x1, const Eigen::Isometry3d& new_from_world) {
  Trajectory t;
  for (double x = x0; x <= x1 + 1e-9; x += 0.5) t.push_back(x, new_from_world * level_frame(x, 11.5, 0.2, 0.0));
  return t;
}

SessionJoinConfig quick() {
  SessionJoinConfig c;
  c.place_spacing_m = 4.0;
  c.cloud_radius_m = 12.0F;
  c.localisation.max_search_points = 300;
  return c;
}

class SessionJoinTest : public ::testing::Test {
 protected:
  SessionJoinTest() {
    // The stored session mapped the left half only, in a frame of its own.
    std::vector<Eigen::Vector3f> left;
    for (const auto& p : sample_plan(two_halves(), 48, 16, 0.1))
      if (p.x() <= 25.0F) left.push_back(p);
    stored = prepare_prior_map(moved(left, stored_from_world));
    index = index_prior_map(stored);
    world = sample_plan(two_halves(), 48, 16, 0.07, 0.01, 9);
  }
  const Eigen::Isometry3d stored_from_world = level_frame(-3.0, 2.0, 0.0, 0.4);
  const Eigen::Isometry3d new_from_world = level_frame(5.0, -7.0, 0.3, -2.2);
  PriorMap stored;
  VoxelHashMap index{0.5F, 1};
  std::vector<Eigen::Vector3f> world;
};

TEST_F(SessionJoinTest, ASessionRunningOutOfTheStoredAreaIsPlacedByItsOverlap) {
  const SessionJoinResult r = join_session(stored, index, moved(world, new_from_world), path(3, 45, new_from_world), quick());
  ASSERT_TRUE(r.success) << r.failure;
  EXPECT_GE(r.places_agreeing, 2);
  EXPECT_LT(r.places_localised, r.places_tried);  // the right half is not in the stored map
  const Eigen::Isometry3d truth = stored_from_world * new_from_world.inverse();
  const Eigen::Isometry3d e = r.stored_from_new.inverse() * truth;
  EXPECT_LT(e.translation().norm(), 0.03);
  EXPECT_LT(Eigen::AngleAxisd(e.linear()).angle(), 0.3 * std::numbers::pi / 180.0);
}

TEST_F(SessionJoinTest, ASessionElsewhereIsRefused) {
  const SessionJoinResult r =
      join_session(stored, index, moved(sample_plan(other_building(), 30, 20, 0.07, 0.01, 5), new_from_world),
                   path(3, 27, new_from_world), quick());
  EXPECT_FALSE(r.success) << "joined at " << r.stored_from_new.translation().transpose();
  EXPECT_FALSE(r.failure.empty());
}

TEST_F(SessionJoinTest, OnePlaceAloneDoesNotJoin) {
  // A short session: its places lie 4 m apart, too close to confirm each other.
  const SessionJoinResult r = join_session(stored, index, moved(world, new_from_world), path(3, 7, new_from_world), quick());
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.failure.find("not confirmed"), std::string::npos) << r.failure;
  EXPECT_GE(r.places_localised, 1);
}

}  // namespace
}  // namespace adit::slam
