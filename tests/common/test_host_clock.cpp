// The step-free host timeline and the watch that counts the wall clock's steps.
#include <gtest/gtest.h>

#include "adit/common/host_clock.hpp"

namespace adit {
namespace {

constexpr std::int64_t kS = 1'000'000'000;

TEST(HostClock, AKernelStampKeepsItsAgeAndAStepInBetweenCostsNothing) {
  const std::int64_t host_now = 500 * kS;
  const std::int64_t wall_now = 1'700'000'000 * kS;
  // Waited 3 ms in the socket: 3 ms before now on the host timeline.
  EXPECT_EQ(HostClock::from_recent_realtime(wall_now - 3'000'000, wall_now, host_now), host_now - 3'000'000);
  // The wall clock stepped 2 s ahead between the kernel's stamp and the read:
  // an age of 2 s is no datagram's; it counts as just received.
  EXPECT_EQ(HostClock::from_recent_realtime(wall_now - 2 * kS - 1000, wall_now, host_now), host_now);
  // Stepped back: the stamp is "in the future".
  EXPECT_EQ(HostClock::from_recent_realtime(wall_now + 2 * kS, wall_now, host_now), host_now);
}

TEST(HostClock, RunsOnTheMonotonicClockFromItsOffset) {
  const HostClock clock(1'700'000'000 * kS);
  const std::int64_t a = clock.now_ns();
  const std::int64_t b = clock.now_ns();
  EXPECT_GE(b, a);
  EXPECT_NEAR(static_cast<double>(a - monotonic_ns()), 1.7e18, 1e9);
  // Two copies share the timeline (the LiDAR's and the CAN feed's).
  const HostClock copy = clock;
  EXPECT_NEAR(static_cast<double>(copy.now_ns() - clock.now_ns()), 0.0, 1e7);
}

TEST(ClockStepWatch, CountsStepsBothWaysButNotSlewing) {
  ClockStepWatch watch;
  std::int64_t mono = 100 * kS;
  std::int64_t wall = 1'700'000'000 * kS;
  EXPECT_FALSE(watch.look(wall, mono));  // the first look sets the reference
  for (int i = 0; i < 100; ++i) {        // 10 s slewed at ntpd's 500 ppm limit
    mono += kS / 10;
    wall += kS / 10 + 50'000;
    EXPECT_FALSE(watch.look(wall, mono));
  }
  mono += kS / 10;
  wall += kS / 10 + 2 * kS;
  EXPECT_EQ(watch.look(wall, mono), 2 * kS);
  mono += kS / 10;
  wall += kS / 10;
  EXPECT_FALSE(watch.look(wall, mono));
  mono += kS / 10;
  wall += kS / 10 - 2 * kS;
  EXPECT_EQ(watch.look(wall, mono), -2 * kS);
}

}  // namespace
}  // namespace adit
