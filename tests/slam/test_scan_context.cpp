#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

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
  EXPECT_LT(ring_key_distance(a.ring_key, b.ring_key), 0.1F);
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

// The search over keyframes with these descriptors, all readable unless `unreadable`.
std::vector<LoopCandidate> search(std::size_t query, const std::vector<ScanContext>& descriptors,
                                  const std::vector<Eigen::Isometry3d>& poses, const std::vector<double>& path,
                                  const std::vector<double>& variance, std::size_t unreadable = SIZE_MAX,
                                  std::size_t* reads = nullptr) {
  std::vector<Eigen::VectorXf> ring_keys;
  for (const ScanContext& d : descriptors) ring_keys.push_back(d.ring_key);
  const DescriptorReader read = [&](std::size_t k, Eigen::MatrixXf& bins) {
    if (reads != nullptr) ++*reads;
    if (k == unreadable) return false;
    bins = descriptors[k].bins;
    return true;
  };
  return find_loop_candidates(query, descriptors[query], {ring_keys, poses, path, variance}, read);
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
  EXPECT_TRUE(search(2, descriptors, poses, path, tight).empty());
  const std::vector<LoopCandidate> found = search(2, descriptors, poses, path, loose);
  ASSERT_FALSE(found.empty());
  EXPECT_EQ(found.front().candidate, 0U);  // by appearance: the other place is within the gate too
}

// Old keyframes' full descriptors are read only for those their ring keys
// keep, and one that cannot be read is passed over.
TEST(PlaceRecognition, OnlyTheKeptFewAreReadAndAnUnreadableOneIsPassedOver) {
  const ScanContext place = make_scan_context(test::scan_of(ring_world(), pose_at(6.0, 0.0, 0.0), 8));
  std::vector<ScanContext> descriptors(30, place);
  std::vector<Eigen::Isometry3d> poses(30, pose_at(6.0, 0.0, 0.0));
  std::vector<double> path, variance(30, 0.0);
  for (int k = 0; k < 30; ++k) path.push_back(40.0 * k);
  std::size_t reads = 0;
  const std::vector<LoopCandidate> all = search(29, descriptors, poses, path, variance, SIZE_MAX, &reads);
  EXPECT_EQ(reads, 10U);  // PlaceRecognitionConfig::ring_key_candidates of the 29 gated
  ASSERT_EQ(all.size(), 3U);
  EXPECT_LT(all.front().descriptor_distance, 1e-6);  // the same place
  const std::size_t best = all.front().candidate;
  const std::vector<LoopCandidate> without = search(29, descriptors, poses, path, variance, best);
  ASSERT_EQ(without.size(), 3U);
  for (const LoopCandidate& c : without) EXPECT_NE(c.candidate, best);
}

TEST(PlaceRecognition, NeighboursAlongThePathAreNotRevisits) {
  const ScanContext place = make_scan_context(test::scan_of(ring_world(), pose_at(6.0, 0.0, 0.0), 10));
  std::vector<ScanContext> descriptors{place, place};
  std::vector<Eigen::Isometry3d> poses{pose_at(6, 0, 0), pose_at(6.5, 0, 0)};
  std::vector<double> path{0.0, 10.0};
  std::vector<double> variance{0.0, 0.01};
  EXPECT_TRUE(search(1, descriptors, poses, path, variance).empty());
}

}  // namespace
}  // namespace adit::slam
