// The Livox IMU adapter (livox_imu.hpp): SDK2 IMU packets (the drivers' encoder)
// into body-frame readings on the host clock, in m/s² and rad/s, through the
// hand-off to the odometry's history; no allocation per packet; damaged and
// unclocked packets counted, not kept.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "adit/daemon/livox_imu.hpp"
#include "adit/drivers/lidar/livox_encoder.hpp"
#include "allocation_counter.hpp"

namespace adit::daemon {
namespace {

constexpr std::int64_t kHostMinusSensor = 1'700'000'000'000'000'000;

using Packet = std::array<std::uint8_t, drivers::kLivoxSdk2ImuPacketBytes>;

Packet packet(std::int64_t sensor_ns, float wander) {
  Packet b{};
  const float gyro[3] = {0.01F, -0.02F, 0.3F + wander};
  const float accel_g[3] = {0.0F, 0.1F + wander, 1.0F};
  drivers::encode_livox_sdk2_imu(sensor_ns, 0, gyro, accel_g, b);
  return b;
}

TEST(LivoxImu, PacketsBecomeBodyFrameReadingsOnTheHostClock) {
  config::Config config;
  config.imu.enabled = true;
  config.lidar.extrinsics.rpy_deg = {0.0, 0.0, 90.0};  // the LiDAR turned left in the body
  const ImuMounting mounting = livox_imu_mounting(drivers::LivoxModel::mid360, config.lidar.extrinsics);
  EXPECT_NEAR(mounting.position_m.x(), -0.02329, 1e-9);  // (11.0, 23.29) mm turned by 90°
  EXPECT_NEAR(mounting.position_m.y(), 0.011, 1e-9);
  LivoxImu imu(config, mounting, false);
  drivers::ClockOffsetEstimator clock;
  const std::int64_t t0 = 5'000'000'000;
  imu.push(packet(t0, 0), t0 + kHostMinusSensor, 0, clock);  // no clock yet: unclocked
  EXPECT_EQ(imu.imu_stats().count(ImuProblem::unclocked), 1U);
  clock.add(t0, t0 + kHostMinusSensor);
  ADIT_REQUIRE_ALLOCATION_COUNTING();
  const auto before = test::allocations();
  for (int i = 0; i < 400; ++i) {
    const std::int64_t t = t0 + 5'000'000LL * i;  // 200 Hz
    clock.add(t, t + kHostMinusSensor);
    imu.push(packet(t, 1e-4F * static_cast<float>(i % 3)), t + kHostMinusSensor, 0, clock);
    if (i % 10 == 0) imu.catch_up(1e30, {});
  }
  EXPECT_EQ(test::allocations() - before, 0U);
  imu.catch_up(1e30, {});
  EXPECT_EQ(imu.imu_stats().samples.load(), 400U);
  EXPECT_NEAR(imu.history().latest(), 1e-9 * static_cast<double>(t0 + 5'000'000LL * 399 + kHostMinusSensor), 1e-6);
  const auto mean = imu.history().mean(imu.history().latest() - 0.5, imu.history().latest());
  ASSERT_TRUE(mean);
  // 0.1 g along the sensor's y is along the body's −x after the 90° turn; 1 g stays on z.
  EXPECT_NEAR(mean->x(), -0.1 * 9.80665, 0.01);
  EXPECT_NEAR(mean->z(), 9.80665, 0.01);
  const Packet damaged = packet(t0, 0);
  imu.push(std::span(damaged.data(), damaged.size() - 1), 0, 0, clock);
  EXPECT_EQ(imu.imu_stats().count(ImuProblem::undecodable), 1U);
}

}  // namespace
}  // namespace adit::daemon
