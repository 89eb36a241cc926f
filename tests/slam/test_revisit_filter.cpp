#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "adit/slam/revisit_filter.hpp"
#include "adit/slam/tiled_map.hpp"

namespace adit::slam {
namespace {

constexpr std::int64_t kSecond = 1'000'000'000;

Eigen::Isometry3d at(double x, double z = 0.0) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(x, 0.0, z);
  return pose;
}

// `count` passes along x from 0 to 20 m, 100 s apart, one keyframe a metre and
// a second: the graph puts all on the truth, the odometry at height z(pass, x).
template <typename Height>
std::shared_ptr<const CorrectionTrack> passes(int count, Height z) {
  std::vector<std::int64_t> stamps;
  std::vector<Eigen::Isometry3d> graph, odometry;
  for (int pass = 0; pass < count; ++pass)
    for (int x = 0; x <= 20; ++x) {
      stamps.push_back((pass * 100 + x) * kSecond);
      graph.push_back(at(x));
      odometry.push_back(at(x, z(pass, x)));
    }
  return std::make_shared<const CorrectionTrack>(stamps, graph, odometry);
}

// Two passes: the odometry had the first `first_drop` m lower per metre
// travelled and the second `second_lift` m higher throughout.
std::shared_ptr<const CorrectionTrack> two_passes(double first_drop, double second_lift) {
  return passes(2, [&](int pass, int x) { return pass == 0 ? -first_drop * x : second_lift; });
}

TEST(RevisitFilter, APointOfTheSecondPassIsPlacedWhereTheFirstPutThatPlace) {
  RevisitFilter filter;
  filter.follow(two_passes(0.0, 0.5));
  // The wall at (10, 2, 1) in truth, seen at t = 110 s: the odometry has it 0.5 m higher.
  const std::vector<Eigen::Vector3f> points{{10.0F, 2.0F, 1.5F}};
  std::vector<Eigen::Vector3f> earlier;
  filter.place_in_earlier_pass(points, 110 * kSecond, earlier);
  ASSERT_EQ(earlier.size(), 1U);
  EXPECT_NEAR((earlier[0] - Eigen::Vector3f(10.0F, 2.0F, 1.0F)).norm(), 0.0F, 1e-5F);
}

TEST(RevisitFilter, AThirdPassIsPlacedWhereTheFirstPutThePlaceNotTheSecond) {
  // Three passes; the odometry 0.5 m higher on the second and 1 m on the third.
  RevisitFilter filter;
  filter.follow(passes(3, [](int pass, int) { return 0.5 * pass; }));
  const std::vector<Eigen::Vector3f> points{{10.0F, 2.0F, 2.0F}};
  std::vector<Eigen::Vector3f> earlier;
  filter.place_in_earlier_pass(points, 210 * kSecond, earlier);
  EXPECT_NEAR(earlier[0].z(), 1.0F, 1e-5F);  // the first pass's frame (the second's would give 1.5)
}

TEST(RevisitFilter, NoEarlierPassWithoutACorrectionTooSoonOrTooFar) {
  RevisitFilter filter;
  std::vector<Eigen::Vector3f> earlier;
  const std::vector<Eigen::Vector3f> points{{10.0F, 2.0F, 1.0F}, {10.0F, 30.0F, 1.0F}};
  filter.place_in_earlier_pass(points, 110 * kSecond, earlier);
  EXPECT_FALSE(earlier[0].allFinite());  // no correction yet
  filter.follow(two_passes(0.0, 0.0));
  filter.place_in_earlier_pass(points, 25 * kSecond, earlier);
  EXPECT_FALSE(earlier[0].allFinite());  // the first pass is less than 30 s old
  filter.place_in_earlier_pass(points, 110 * kSecond, earlier);
  EXPECT_TRUE(earlier[0].allFinite());
  EXPECT_FALSE(earlier[1].allFinite());  // 30 m from the route: beyond the 10 m radius
}

TEST(RevisitFilter, AFarPointIsMatchedToTheKeyframeBesideItNotTheSensors) {
  RevisitFilter filter;
  filter.follow(two_passes(0.02, 0.0));  // the first pass sank 2 cm a metre: 0.36 m at x = 18
  const std::vector<Eigen::Vector3f> points{{18.0F, 2.0F, 1.0F}};
  std::vector<Eigen::Vector3f> earlier;
  filter.place_in_earlier_pass(points, 102 * kSecond, earlier);
  EXPECT_NEAR(earlier[0].z(), 1.0F - 0.36F, 1e-4F);  // not 1 − 0.04, the first pass's drift at x = 2
}

TEST(RevisitFilter, ASecondPassDriftedByHalfAMetreAddsNothingTheFirstMapped) {
  const auto track = two_passes(0.0, 0.5);
  RevisitFilter filter;
  filter.follow(track);
  TiledVoxelMap map({20.0F, 0.05F, 1});
  // A wall along the route at y = 2, 0-3 m high, a point every 2 cm.
  std::vector<Eigen::Vector3f> wall;
  for (int i = 0; i < 1000; ++i)
    for (int j = 0; j < 150; ++j) wall.push_back({0.02F * static_cast<float>(i), 2.0F, 0.02F * static_cast<float>(j)});
  map.add(wall, {}, 10.0);
  const std::size_t first = map.size();
  // The second pass sees the same wall 0.5 m higher in the odometry's frame, and a new shelf at y = 1.5.
  std::vector<Eigen::Vector3f> again;
  for (const Eigen::Vector3f& p : wall) again.push_back(p + Eigen::Vector3f(0.0F, 0.0F, 0.5F));
  for (int i = 0; i < 100; ++i) again.push_back({5.02F + 0.1F * static_cast<float>(i), 1.52F, 1.52F});
  std::vector<Eigen::Vector3f> earlier;
  filter.place_in_earlier_pass(again, 110 * kSecond, earlier);
  std::vector<std::uint8_t> held;
  map.holds(earlier, held);
  std::vector<Eigen::Vector3f> kept;
  for (std::size_t i = 0; i < again.size(); ++i)
    if (held[i] == 0) kept.push_back(again[i]);
  EXPECT_EQ(kept.size(), 100U);  // the shelf only
  map.add(kept, {}, 110.0);
  EXPECT_EQ(map.size(), first + 100U);
  // Unfiltered, the second pass would have added the wall again beside the first.
  TiledVoxelMap unfiltered({20.0F, 0.05F, 1});
  unfiltered.add(wall, {}, 10.0);
  unfiltered.add(again, {}, 110.0);
  EXPECT_GT(unfiltered.size(), first + 2000U);
}

}  // namespace
}  // namespace adit::slam
