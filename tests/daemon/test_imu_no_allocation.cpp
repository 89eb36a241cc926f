// The IMU's per-reading path allocates nothing once built: the Ouster IMU's
// push (decode, clock, checks, mounting, hand-off) and the odometry's
// catch_up, and the CAN IMU's pairing and checks.
#include <gtest/gtest.h>

#include <array>
#include <cstring>

#include "adit/daemon/can_imu_pairing.hpp"
#include "adit/daemon/imu_monitor.hpp"
#include "adit/daemon/ouster_imu.hpp"
#include "adit/drivers/lidar/ouster_packet.hpp"
#include "allocation_counter.hpp"

namespace adit::daemon {
namespace {

std::array<std::uint8_t, drivers::kOusterImuPacketBytes> imu_packet(std::uint64_t t_ns, float wander) {
  std::array<std::uint8_t, drivers::kOusterImuPacketBytes> b{};
  const std::uint64_t stamps[3] = {t_ns, t_ns + 200'000, t_ns + 400'000};
  const float values[6] = {0.01F + wander, -0.02F, 1.0F, 0.5F, -0.25F + wander, 0.1F};
  std::memcpy(b.data(), stamps, 24);
  std::memcpy(b.data() + 24, values, 24);
  return b;
}

TEST(ImuNoAllocation, OusterImuPacketsToTheOdometryAllocateNothing) {
  ADIT_REQUIRE_ALLOCATION_COUNTING();
  drivers::OusterMetadata metadata;
  metadata.imu_to_sensor = {1, 0, 0, 6.253, 0, 1, 0, -11.775, 0, 0, 1, 7.645, 0, 0, 0, 1};
  config::Config config;
  config.imu.enabled = true;
  config.imu.source = config::ImuSource::ouster;
  OusterImu imu(config, metadata, false);
  drivers::ClockOffsetEstimator clock;
  clock.add(1'000'000'000, 1'700'000'001'000'000'000);
  const auto before = test::allocations();
  for (int i = 0; i < 2000; ++i) {
    const std::uint64_t t = 1'000'000'000ULL + 10'000'000ULL * static_cast<std::uint64_t>(i);
    const auto packet = imu_packet(t, 1e-4F * static_cast<float>(i % 7));
    const std::int64_t host = 1'700'000'000'000'000'000 + static_cast<std::int64_t>(t);
    clock.add(static_cast<std::int64_t>(t), host);  // the LiDAR's packets, going on beside the IMU's
    imu.push(packet, host, 0, clock);
    if (i % 10 == 0) imu.catch_up(1e30, {});
  }
  EXPECT_EQ(test::allocations() - before, 0U);
  EXPECT_EQ(imu.imu_stats().samples.load(), 2000U);
  EXPECT_EQ(imu.imu_stats().count(ImuProblem::gap), 0U);
}

TEST(ImuNoAllocation, CanImuPairingAndChecksAllocateNothing) {
  ADIT_REQUIRE_ALLOCATION_COUNTING();
  ImuStats stats;
  ImuMonitor monitor(stats, ImuLimits{39.2, 8.7});
  CanImuPairing pairing(true);
  std::uint64_t kept = 0;
  const auto before = test::allocations();
  for (int i = 0; i < 2000; ++i) {
    const double t = 1000.0 + 0.01 * i;
    const Eigen::Vector3d f(0.1 + 0.001 * (i % 5), -0.2, 9.8);
    const Eigen::Vector3d w(0.01, -0.02 + 0.0002 * (i % 3), 0.5);
    pairing.add_accel(t, f);
    const CanImuPairing::Result r = pairing.add_gyro(t + 1e-4, w);
    if (r.reading && monitor.check(*r.reading, static_cast<std::uint64_t>(i))) ++kept;
  }
  EXPECT_EQ(test::allocations() - before, 0U);
  EXPECT_EQ(kept, 2000U);
  EXPECT_EQ(stats.count(ImuProblem::stuck_axis), 4U) << "ay, az, gx and gz read the same every time (once each)";
}

}  // namespace
}  // namespace adit::daemon
