// After warm-up, Odometry::process allocates nothing: every global operator
// new in this test binary is counted while steady-state scans are processed.

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>

#include "adit/slam/odometry.hpp"
#include "synthetic_scenes.hpp"

namespace {
std::atomic<long> g_allocations{0};  // test instrumentation only
}

void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace adit::slam {
namespace {

TEST(OdometryAllocations, SteadyStateProcessingAllocatesNothing) {
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
  for (int k = 0; k < 5; ++k) {  // warm-up
    fill(0.1 * k);
    ASSERT_TRUE(odometry.process({k * 100'000'000LL, scan, times}).valid);
  }
  long allocations = 0;
  for (int k = 5; k < 15; ++k) {
    fill(0.1 * k);
    const long before = g_allocations.load();
    const OdometryResult r = odometry.process({k * 100'000'000LL, scan, times});
    allocations += g_allocations.load() - before;
    ASSERT_TRUE(r.valid);
  }
  EXPECT_EQ(allocations, 0);
}

}  // namespace
}  // namespace adit::slam
