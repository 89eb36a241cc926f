#include <gtest/gtest.h>

#include <cmath>

#include "adit/slam/place_recognition.hpp"
#include "adit/slam/scan_context.hpp"
#include "loop_scenes.hpp"
#include "synthetic_scenes.hpp"

namespace adit::slam {
namespace {

using test::pose_at;

double angle_diff(double a, double b) { return std::abs(std::remainder(a - b, 2 * M_PI)); }

const std::vector<Eigen::Vector3f>& ring_world() {
  static const std::vector<Eigen::Vector3f> world = test::ring_corridor(30.0F, 40, 7);
  return world;
}

TEST(ScanContext, BinsHoldTheHighestPointAndTheRingKeyItsOccupancy) {
  const std::vector<Eigen::Vector3f> points{{1.0F, 0.1F, -1.0F}, {1.0F, 0.1F, 0.5F}, {-1.0F, 0.1F, -1.0F}};
  ScanContextConfig config;
  config.rings = 2;
  config.sectors = 4;
  config.max_radius_m = 4.0F;
  const ScanContext sc = make_scan_context(points, config);
  EXPECT_FLOAT_EQ(sc.bins(0, 0), 2.5F);  // 0.5 above the lowest (-1.0), plus 1
  EXPECT_FLOAT_EQ(sc.bins(0, 1), 1.0F);  // azimuth just under 180°: sector 1 of 4
  EXPECT_EQ((sc.bins.array() > 0).count(), 2);
  EXPECT_FLOAT_EQ(sc.ring_key[0], 0.5F);
  EXPECT_FLOAT_EQ(sc.ring_key[1], 0.0F);
}

// The same place seen turned by 72° (12 sectors): the columns shift, the
// match finds the yaw, and the ring key is unchanged.
TEST(ScanContext, ATurnOnTheSpotIsAColumnShift) {
  const Eigen::Isometry3d here = pose_at(10.0, 0.3, 0.0);
  const Eigen::Isometry3d turned = pose_at(10.0, 0.3, 72.0 * M_PI / 180.0);
  const ScanContext a = make_scan_context(test::scan_of(ring_world(), here, 1));
  const ScanContext b = make_scan_context(test::scan_of(ring_world(), turned, 2));
  const ScanContextMatch m = compare(b, a);
  EXPECT_LT(m.distance, 0.1);
  EXPECT_LT(angle_diff(m.yaw_rad, 72.0 * M_PI / 180.0), 7.0 * M_PI / 180.0);
  EXPECT_LT(ring_key_distance(a, b), 0.1F);
}

// A corridor driven back the other way, half a metre aside: the best shift
// is 180°, and the distance is as small as for a revisit in the same direction.
TEST(ScanContext, AReverseRevisitMatchesAtHalfATurn) {
  const ScanContext forward = make_scan_context(test::scan_of(ring_world(), pose_at(12.0, 0.0, 0.0), 3));
  const ScanContext back = make_scan_context(test::scan_of(ring_world(), pose_at(12.3, 0.5, M_PI), 4));
  const ScanContextMatch m = compare(back, forward);
  EXPECT_LT(m.distance, 0.2);
  EXPECT_LT(angle_diff(m.yaw_rad, M_PI), 7.0 * M_PI / 180.0);
}

// Another stretch of the same ring, 12 m on, with other pillars: farther
// than the revisits above.
TEST(ScanContext, AnotherStretchIsFarther) {
  const ScanContext a = make_scan_context(test::scan_of(ring_world(), pose_at(6.0, 0.0, 0.0), 5));
  const ScanContext same = make_scan_context(test::scan_of(ring_world(), pose_at(6.2, 0.1, 0.0), 6));
  const ScanContext other = make_scan_context(test::scan_of(ring_world(), pose_at(18.0, 0.0, 0.0), 7));
  EXPECT_LT(compare(same, a).distance + 0.05, compare(other, a).distance);
}

// Candidates are sought only where the graph's uncertainty lets the query
// be: the same scan, far from the query by the graph, is not a candidate
// until the accumulated variance says the graph could be that wrong.
TEST(PlaceRecognition, TheGateFollowsTheGraphsUncertainty) {
  const ScanContext place = make_scan_context(test::scan_of(ring_world(), pose_at(6.0, 0.0, 0.0), 8));
  const ScanContext other = make_scan_context(test::scan_of(ring_world(), pose_at(20.0, 0.0, 0.0), 9));
  std::vector<ScanContext> descriptors{place, other, place};
  std::vector<Eigen::Isometry3d> poses{pose_at(0, 0, 0), pose_at(20, 0, 0), pose_at(10.0, 0.0, 0.0)};  // the query 10 m off by the graph
  std::vector<double> path{0.0, 40.0, 100.0};
  std::vector<double> tight{0.0, 0.1, 0.2};
  std::vector<double> loose{0.0, 5.0, 16.0};  // σ 4 m per axis between 0 and 2
  EXPECT_TRUE(find_loop_candidates(2, {descriptors, poses, path, tight}).empty());
  const std::vector<LoopCandidate> found = find_loop_candidates(2, {descriptors, poses, path, loose});
  ASSERT_FALSE(found.empty());
  EXPECT_EQ(found.front().candidate, 0U);  // by appearance: the other place is within the gate too
}

TEST(PlaceRecognition, NeighboursAlongThePathAreNotRevisits) {
  const ScanContext place = make_scan_context(test::scan_of(ring_world(), pose_at(6.0, 0.0, 0.0), 10));
  std::vector<ScanContext> descriptors{place, place};
  std::vector<Eigen::Isometry3d> poses{pose_at(6, 0, 0), pose_at(6.5, 0, 0)};
  std::vector<double> path{0.0, 10.0};
  std::vector<double> variance{0.0, 0.01};
  EXPECT_TRUE(find_loop_candidates(1, {descriptors, poses, path, variance}).empty());
}

}  // namespace
}  // namespace adit::slam
