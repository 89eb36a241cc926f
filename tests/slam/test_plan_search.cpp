// The plan search's branch and bound (slam/plan_search.hpp): at every depth it
// finds the exhaustive search's peaks, bit for bit, with or without a hint, and
// sums far fewer cells.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "adit/slam/plan_search.hpp"
#include "adit/slam/prior_map.hpp"
#include "plan_scene.hpp"

namespace adit::slam {
namespace {

using namespace plan_scene;

// The wall points a sensor at (x, y, yaw) sees, in its levelled frame.
std::vector<Eigen::Vector3f> walls_seen(const std::vector<Eigen::Vector3f>& world, double x, double y, double yaw) {
  std::vector<Eigen::Vector3f> walls;
  for (const Eigen::Vector3f& p : cloud_at(world, pose_at(x, y, yaw), 15.0F))
    if (p.z() > -1.0F && p.z() < 1.6F) walls.push_back(p);  // the floor lies 1.2 m below, the ceiling 1.8 m above
  return walls;
}

void expect_same_peaks(const PlanSearch& got, const PlanSearch& exhaustive) {
  ASSERT_EQ(got.peaks.size(), exhaustive.peaks.size());
  for (std::size_t k = 0; k < got.peaks.size(); ++k) {
    SCOPED_TRACE(k);
    EXPECT_EQ(got.peaks[k].score, exhaustive.peaks[k].score);
    EXPECT_EQ(got.peaks[k].ix, exhaustive.peaks[k].ix);
    EXPECT_EQ(got.peaks[k].iy, exhaustive.peaks[k].iy);
    EXPECT_EQ(got.peaks[k].yaw, exhaustive.peaks[k].yaw);
  }
  EXPECT_EQ(got.cells, exhaustive.cells);
}

// 200 search points (600 in aditd) and four starts: the exhaustive oracle is
// slow under the sanitizers (six starts at 600 took 201 s under ASan).
TEST(PlanSearch, BranchAndBoundFindsTheExhaustiveSearchsPeaksAndSumsFarFewerCells) {
  const PriorMap prior = prepare_prior_map(sample_plan(office(), 24, 16, 0.1));
  const std::vector<Eigen::Vector3f> world = sample_plan(office(), 24, 16, 0.07, 0.01, 7);
  std::mt19937 rng(76);
  std::uniform_real_distribution<double> x(1.5, 22.5), y(1.5, 14.5), yaw(-std::numbers::pi, std::numbers::pi);
  LocalisationConfig base;
  base.max_search_points = 200;
  std::uint64_t sums = 0, cells = 0;
  for (int start = 0; start < 4; ++start) {
    const double sx = x(rng), sy = y(rng), syaw = yaw(rng);
    SCOPED_TRACE(testing::Message() << "start (" << sx << ", " << sy << "), yaw " << syaw);
    const std::vector<Eigen::Vector3f> walls = walls_seen(world, sx, sy, syaw);
    LocalisationConfig exhaustive = base;
    exhaustive.search_levels = 0;
    const PlanSearch reference = search_plan(walls, prior.plan, std::nullopt, exhaustive);
    ASSERT_FALSE(reference.peaks.empty());
    EXPECT_EQ(reference.sums, reference.cells);
    for (const int levels : {1, 4, 6}) {
      SCOPED_TRACE(testing::Message() << levels << " levels");
      LocalisationConfig config = base;
      config.search_levels = levels;
      const PlanSearch got = search_plan(walls, prior.plan, std::nullopt, config);
      expect_same_peaks(got, reference);
      if (levels == LocalisationConfig{}.search_levels) {
        sums += got.sums;
        cells += got.cells;
      }
    }
    // A hint's disc and yaw range, off the truth by a metre and 5°.
    LocalisationHint hint;
    hint.position = Eigen::Vector2d(sx + 0.6, sy - 0.8);
    hint.radius_m = 3.0;
    hint.yaw_rad = syaw + 5.0 * std::numbers::pi / 180.0;
    hint.yaw_tolerance_rad = 0.3;
    const PlanSearch hinted_reference = search_plan(walls, prior.plan, hint, exhaustive);
    expect_same_peaks(search_plan(walls, prior.plan, hint, base), hinted_reference);
    // The best peak is the start, within a cell and a yaw step or two.
    const PlanPeak& best = reference.peaks.front();
    const double cx = prior.plan.origin.x() + (best.ix + 0.5) * prior.plan.cell_m;
    const double cy = prior.plan.origin.y() + (best.iy + 0.5) * prior.plan.cell_m;
    EXPECT_LT(std::hypot(cx - sx, cy - sy), 0.4);
    EXPECT_LT(std::abs(std::remainder(best.yaw - syaw, 2.0 * std::numbers::pi)), 0.05);
  }
  // Measured: decision 076. Loose here: the bound must prune most of the plan.
  EXPECT_LT(static_cast<double>(sums), 0.25 * static_cast<double>(cells)) << sums << " sums for " << cells << " cells";
}

// The fields hold the likelihood in bytes (decision 077): each peak's score is
// the mean likelihood of its search points to within half a level.
TEST(PlanSearch, AScoreIsTheMeanLikelihoodToWithinHalfALevel) {
  const PriorMap prior = prepare_prior_map(sample_plan(office(), 24, 16, 0.1));
  const std::vector<Eigen::Vector3f> world = sample_plan(office(), 24, 16, 0.07, 0.01, 7);
  std::vector<Eigen::Vector3f> walls = walls_seen(world, 7.3, 5.1, 0.4);
  LocalisationConfig config;
  ASSERT_GT(walls.size(), 120U);
  walls.resize(120);  // all of them search points (config.max_search_points is more)
  config.search_levels = 0;
  const PlanSearch got = search_plan(walls, prior.plan, std::nullopt, config);
  ASSERT_FALSE(got.peaks.empty());
  const PlanGrid& plan = prior.plan;
  for (const PlanPeak& peak : got.peaks) {
    SCOPED_TRACE(testing::Message() << "peak at (" << peak.ix << ", " << peak.iy << "), yaw " << peak.yaw);
    // The search's own cell arithmetic: the point turned by the yaw, in cells from the peak's cell.
    const Eigen::Matrix2f m = Eigen::Rotation2Df(static_cast<float>(peak.yaw)).toRotationMatrix();
    double sum = 0.0;
    for (const Eigen::Vector3f& p : walls) {
      const Eigen::Vector2f q = m * p.head<2>() * (1.0F / plan.cell_m);
      const long ix = peak.ix + std::lround(q.x());
      const long iy = peak.iy + std::lround(q.y());
      if (ix >= 0 && iy >= 0 && ix < plan.width && iy < plan.height)
        sum += plan.likelihood[plan.index(static_cast<int>(ix), static_cast<int>(iy))];
    }
    EXPECT_NEAR(peak.score, sum / static_cast<double>(walls.size()), 0.5 / 255.0 + 1e-9);
  }
}

}  // namespace
}  // namespace adit::slam
