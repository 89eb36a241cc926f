// After warm-up, Odometry::process allocates nothing: every global operator
// new in this test binary is counted while steady-state scans are processed,
// with and without a prior map (Odometry::anchor_to_prior).

#include <gtest/gtest.h>

#include <random>

#include "adit/slam/odometry.hpp"
#include "allocation_counter.hpp"
#include "synthetic_scenes.hpp"

namespace adit::slam {
namespace {

void steady_state_allocates_nothing(bool anchored) {
  ADIT_REQUIRE_ALLOCATION_COUNTING();
  const auto hall = test::room(200000, 31, 20.0F, 10.0F, 4.0F);
  OdometryConfig config;
  config.max_range_m = 30.0F;
  config.max_scan_points = 30000;
  Odometry odometry(config);
  std::mt19937 rng(5);
  std::uniform_int_distribution<std::size_t> pick(0, hall.size() - 1);
  std::vector<Eigen::Vector3f> scan(20000);
  std::vector<float> times(scan.size());
  const auto fill = [&](double x) {
    for (std::size_t i = 0; i < scan.size(); ++i) {
      scan[i] = hall[pick(rng)] - Eigen::Vector3f(static_cast<float>(x), 0.0F, 0.0F);
      times[i] = 0.1F * static_cast<float>(i) / static_cast<float>(scan.size());
    }
  };
  // Anchored to a prior map (the hall itself), as once localised against one.
  VoxelHashMap prior(0.5F, 1 << 16);
  prior.add(hall);
  if (anchored) odometry.anchor_to_prior(prior, Eigen::Isometry3d::Identity());
  for (int k = 0; k < 5; ++k) {  // warm-up
    fill(0.1 * k);
    ASSERT_TRUE(odometry.process({k * 100'000'000LL, scan, times}).valid);
  }
  std::uint64_t allocations = 0;
  for (int k = 5; k < 15; ++k) {
    fill(0.1 * k);
    const std::uint64_t before = adit::test::allocations();
    const OdometryResult r = odometry.process({k * 100'000'000LL, scan, times});
    allocations += adit::test::allocations() - before;
    ASSERT_TRUE(r.valid);
    if (anchored) {
      ASSERT_GT(r.registration.prior_correspondences, 0);
    }
  }
  EXPECT_EQ(allocations, 0U);
}

TEST(OdometryAllocations, SteadyStateProcessingAllocatesNothing) { steady_state_allocates_nothing(false); }

TEST(OdometryAllocations, AnchoredToAPriorMapItAllocatesNothingEither) { steady_state_allocates_nothing(true); }

}  // namespace
}  // namespace adit::slam
