// Prior maps: preparation and its checks, the prepared file, global
// localisation (found where the scene allows it; refused, never wrong, where
// it is symmetric or another building) and the deviations of a moved wall.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <vector>

#include "adit/common/error.hpp"
#include "adit/slam/global_localisation.hpp"
#include "adit/slam/prior_deviations.hpp"
#include "adit/slam/prior_map.hpp"
#include "adit/slam/prior_map_file.hpp"
#include "plan_scene.hpp"

namespace adit::slam {
namespace {

using namespace plan_scene;

LocalisationConfig quick() {
  LocalisationConfig c;
  c.max_search_points = 300;
  return c;
}

class PriorMapTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    prior_ = new PriorMap(prepare_prior_map(sample_plan(office(), 24, 16, 0.1)));
    world_ = new std::vector<Eigen::Vector3f>(sample_plan(office(), 24, 16, 0.07, 0.01, 7));
  }
  static void TearDownTestSuite() {
    delete prior_;
    delete world_;
  }
  static PriorMap* prior_;
  static std::vector<Eigen::Vector3f>* world_;
};
PriorMap* PriorMapTest::prior_ = nullptr;
std::vector<Eigen::Vector3f>* PriorMapTest::world_ = nullptr;

TEST_F(PriorMapTest, PreparedMapPassesItsChecksAndHasAPlan) {
  EXPECT_EQ(check_prior_map(*prior_), "");
  EXPECT_GT(prior_->vertical_points, prior_->points.size() / 4);
  EXPECT_GT(prior_->horizontal_points, prior_->points.size() / 4);
  // A cell on a wall is likely, a cell in the middle of a room is not.
  const PlanGrid& g = prior_->plan;
  const auto cell = [&](double x, double y) {
    return g.index(static_cast<int>((x - g.origin.x()) / g.cell_m), static_cast<int>((y - g.origin.y()) / g.cell_m));
  };
  EXPECT_GT(g.likelihood[cell(8.05, 5.0)], 0.8F);
  EXPECT_EQ(g.likelihood[cell(4.0, 5.0)], 0.0F);
  EXPECT_NEAR(g.floor_z[cell(4.0, 5.0)], 0.0F, 1e-3F);
}

TEST_F(PriorMapTest, WrongUnitsAndAxesAreNamed) {
  std::vector<Eigen::Vector3f> mm, y_up;
  for (const auto& p : prior_->points) {
    mm.push_back(1000.0F * p);
    y_up.emplace_back(p.x(), p.z(), p.y());
  }
  EXPECT_NE(check_prior_map(prepare_prior_map(mm)).find("millimetres"), std::string::npos);
  const std::string y_up_problem = check_prior_map(prepare_prior_map(y_up));
  EXPECT_NE(y_up_problem.find("Y-up"), std::string::npos) << y_up_problem;
  EXPECT_THROW(prepare_prior_map(std::vector<Eigen::Vector3f>{}), std::invalid_argument);
}

TEST_F(PriorMapTest, FileRoundTripAndTruncation) {
  const auto dir = std::filesystem::temp_directory_path() / "adit_test_prior_map";
  write_prior_map(dir, *prior_);
  const PriorMap back = read_prior_map(dir);
  EXPECT_EQ(back.points, prior_->points);
  EXPECT_EQ(back.normals, prior_->normals);
  EXPECT_EQ(back.plan.likelihood, prior_->plan.likelihood);
  EXPECT_EQ(back.plan.width, prior_->plan.width);
  const auto file = dir / kPriorMapFile;
  std::filesystem::resize_file(file, std::filesystem::file_size(file) / 2);
  EXPECT_THROW(read_prior_map(dir), InputError);
  std::ofstream(file) << "not a prior";
  EXPECT_THROW(read_prior_map(file), InputError);
}

TEST_F(PriorMapTest, FoundFromAnUnknownStart) {
  const VoxelHashMap index = index_prior_map(*prior_);
  for (const auto& truth : {pose_at(4.0, 5.0, 0.7), pose_at(19.0, 2.5, -2.4)}) {
    const LocalisationResult r = localise(cloud_at(*world_, truth, 15.0F), *prior_, index, std::nullopt, quick());
    ASSERT_TRUE(r.success) << r.failure;
    const Eigen::Isometry3d e = r.pose.inverse() * truth;
    EXPECT_LT(e.translation().norm(), 0.03);
    EXPECT_LT(Eigen::AngleAxisd(e.linear()).angle(), 0.3 * std::numbers::pi / 180.0);
  }
}

TEST_F(PriorMapTest, AHintNarrowsTheSearch) {
  const VoxelHashMap index = index_prior_map(*prior_);
  const Eigen::Isometry3d truth = pose_at(4.0, 5.0, 0.7);
  LocalisationHint hint;
  hint.position = Eigen::Vector2d(4.5, 4.6);
  hint.radius_m = 1.5;
  hint.yaw_rad = 0.8;
  hint.yaw_tolerance_rad = 0.2;
  const LocalisationResult r = localise(cloud_at(*world_, truth, 15.0F), *prior_, index, hint, quick());
  ASSERT_TRUE(r.success) << r.failure;
  EXPECT_LT((r.pose.inverse() * truth).translation().norm(), 0.03);
  // A hint far from the truth: nothing there matches, and it says so.
  hint.position = Eigen::Vector2d(20.0, 13.0);
  EXPECT_FALSE(localise(cloud_at(*world_, truth, 15.0F), *prior_, index, hint, quick()).success);
}

TEST_F(PriorMapTest, SymmetricRoomIsAmbiguousNotWrong) {
  // A plain 20 x 10 m hall: a sensor at its centre sees the same from two headings 180° apart.
  const std::vector<Wall> hall{{0, 0, 20, 0}, {20, 0, 20, 10}, {20, 10, 0, 10}, {0, 10, 0, 0}};
  const PriorMap prior = prepare_prior_map(sample_plan(hall, 20, 10, 0.1));
  const VoxelHashMap index = index_prior_map(prior);
  const LocalisationResult r =
      localise(cloud_at(sample_plan(hall, 20, 10, 0.07, 0.01, 3), pose_at(10.0, 5.0, 0.3), 30.0F), prior, index,
               std::nullopt, quick());
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.failure.find("ambiguous"), std::string::npos) << r.failure;
}

TEST_F(PriorMapTest, AnotherBuildingIsRefused) {
  std::vector<Wall> other{{0, 0, 30, 0}, {30, 0, 30, 20}, {30, 20, 0, 20}, {0, 20, 0, 0}, {15, 0, 15, 7}};
  add_box(other, 7, 14, 1.0);
  add_box(other, 23, 9, 0.5);
  const PriorMap prior = prepare_prior_map(sample_plan(other, 30, 20, 0.1));
  const VoxelHashMap index = index_prior_map(prior);
  const LocalisationResult r = localise(cloud_at(*world_, pose_at(4.0, 5.0, 0.7), 15.0F), prior, index, std::nullopt, quick());
  EXPECT_FALSE(r.success) << "reported found at " << r.pose.translation().transpose();
  EXPECT_FALSE(r.failure.empty());
}

TEST_F(PriorMapTest, TooLittleSeenIsRefused) {
  const VoxelHashMap index = index_prior_map(*prior_);
  const LocalisationResult r = localise(cloud_at(*world_, pose_at(4.0, 5.0, 0.7), 0.8F), *prior_, index, std::nullopt, quick());
  EXPECT_FALSE(r.success);
}

TEST_F(PriorMapTest, MovedWallIsTheDeviatingRegion) {
  // As built: the wall at x = 8 stands 0.3 m further in +x, towards the observers (on its +x side).
  const std::vector<Eigen::Vector3f> built = sample_plan(office(0.3), 24, 16, 0.07, 0.01, 5);
  const std::vector<Eigen::Vector3f> views{Eigen::Vector3f(12, 8, 1.2), Eigen::Vector3f(20, 3, 1.2)};
  const std::vector<float> dev = signed_deviations(built, views, *prior_);
  DeviationConfig config;
  std::vector<int> member(built.size());
  const std::vector<DeviationRegion> regions = deviation_regions(built, dev, config, member);
  ASSERT_FALSE(regions.empty());
  const DeviationRegion& wall = regions.front();
  // The wall, and the strip of floor and ceiling it left (where the design's wall foot is nearest).
  EXPECT_NEAR(wall.centroid.x(), 8.15F, 0.4F);
  EXPECT_GT(wall.mean_m, 0.2F) << wall.mean_m << " over " << wall.points;  // in front of the design: towards the observers
  EXPECT_LT(wall.mean_m, 0.32F);
  EXPECT_GT(wall.hi.y() - wall.lo.y(), 9.0F);
  // Unchanged surfaces stay within the noise, at the design's corners too (where the nearest prior point's
  // normal was fitted across two faces, or none fits, the nearest patch of the point's own face measures it).
  std::size_t unchanged = 0, quiet = 0, deviating = 0;
  for (std::size_t i = 0; i < built.size(); ++i) {
    if (std::abs(built[i].x() - 8.3F) < 0.5F) continue;
    ++unchanged;
    quiet += std::abs(dev[i]) < 0.03F ? 1 : 0;
    deviating += std::abs(dev[i]) > config.threshold_m ? 1 : 0;
  }
  EXPECT_GT(static_cast<double>(quiet), 0.95 * static_cast<double>(unchanged));
  EXPECT_LT(static_cast<double>(deviating), 0.001 * static_cast<double>(unchanged)) << deviating << " of " << unchanged;
}

// Range noise puts a few percent of an unchanged wall's points past the
// threshold, scattered over it; they are no region. A patch that really
// deviates is one, and only its points are members.
TEST(DeviationRegions, ScatteredNoiseIsNoRegionAPatchIs) {
  std::vector<Eigen::Vector3f> wall;
  std::vector<float> dev;
  for (int i = 0; i < 500; ++i)
    for (int k = 0; k < 150; ++k) {  // 10 x 3 m every 2 cm
      const float x = 0.02F * static_cast<float>(i), z = 0.02F * static_cast<float>(k);
      wall.emplace_back(x, 0.0F, z);
      const bool patch = x >= 6.0F && x < 7.0F && z >= 1.0F && z < 2.0F;
      dev.push_back(patch ? 0.2F : ((i * 150 + k) % 31 == 0 ? 0.06F : 0.01F));  // 3 % noise past 5 cm
    }
  DeviationConfig config;
  std::vector<int> member(wall.size());
  const std::vector<DeviationRegion> regions = deviation_regions(wall, dev, config, member);
  ASSERT_EQ(regions.size(), 1U);
  EXPECT_NEAR(regions[0].centroid.x(), 6.5F, 0.05F);
  EXPECT_NEAR(regions[0].centroid.z(), 1.5F, 0.05F);
  EXPECT_EQ(regions[0].points, 2500U);  // the patch's 50 x 50 points
  std::size_t members_off_the_patch = 0;
  for (std::size_t i = 0; i < wall.size(); ++i) members_off_the_patch += (member[i] >= 0 && dev[i] != 0.2F) ? 1 : 0;
  EXPECT_EQ(members_off_the_patch, 0U);
}

}  // namespace
}  // namespace adit::slam
