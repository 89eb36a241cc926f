// Zero heap allocations per packet for the Livox decoders in the live path
// (decode + assemble through DecodeStream, IMU packets among the points). This
// binary replaces the global operator new to count every allocation.
#include <gtest/gtest.h>

#include <vector>

#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/livox.hpp"
#include "adit/drivers/lidar/livox_encoder.hpp"
#include "allocation_counter.hpp"

namespace adit::drivers {
namespace {

std::vector<std::vector<std::uint8_t>> stream_of(LivoxModel model, int packets) {
  std::vector<std::vector<std::uint8_t>> out;
  std::vector<LivoxRawPoint> pts(96, LivoxRawPoint{4000, 1000, -200, 50, 0});
  const std::int64_t t0 = 1'700'000'000'000'000'000;
  const float gyro[3] = {0, 0, 0.1F};
  const float acc[3] = {0, 0, 1};
  for (int k = 0; k < packets; ++k) {
    if (model == LivoxModel::mid360) {
      LivoxSdk2PointPacket in;
      in.time_ns = t0 + k * 480'000LL;
      in.time_interval = 4800;
      in.udp_cnt = static_cast<std::uint16_t>(k);
      in.points = pts;
      out.emplace_back(livox_sdk2_point_packet_bytes(pts.size()));
      encode_livox_sdk2_points(in, out.back());
      if (k % 10 == 0) {
        out.emplace_back(kLivoxSdk2ImuPacketBytes);
        encode_livox_sdk2_imu(in.time_ns, static_cast<std::uint16_t>(k), gyro, acc, out.back());
      }
    } else {
      out.emplace_back(kLivoxSdk1PointPacketBytes);
      encode_livox_sdk1_points(t0 + k * 400'032LL, false, std::span<const LivoxRawPoint, 96>(pts.data(), 96),
                               out.back());
      if (k % 10 == 0) {
        out.emplace_back(kLivoxSdk1ImuPacketBytes);
        encode_livox_sdk1_imu(t0 + k * 400'032LL, gyro, acc, out.back());
      }
    }
  }
  return out;
}

void expect_no_allocation(LivoxModel model) {
  ADIT_REQUIRE_ALLOCATION_COUNTING();
  const auto packets = stream_of(model, 2000);  // ~1 s of points
  LivoxDecoder decoder(model);
  ScanAssembler assembler(assembler_config_for(decoder, livox_packet_period_ns(model, packets.front()), 0.0F));
  std::uint64_t scans = 0;
  DecodeStream stream(decoder, assembler, [&](LidarScan&) { ++scans; });
  const std::size_t warm_up = packets.size() / 4;
  std::int64_t host = 1'700'000'000'000'000'000;
  for (std::size_t i = 0; i < warm_up; ++i) stream.push(packets[i], host += 400'000);
  const std::uint64_t before = adit::test::allocations();
  const std::uint64_t scans_before = scans;
  for (std::size_t i = warm_up; i < packets.size(); ++i) stream.push(packets[i], host += 400'000);
  EXPECT_EQ(adit::test::allocations() - before, 0u);
  EXPECT_GE(scans - scans_before, 4u);
}

TEST(LivoxNoAllocation, Mid360) { expect_no_allocation(LivoxModel::mid360); }
TEST(LivoxNoAllocation, Avia) { expect_no_allocation(LivoxModel::avia); }

}  // namespace
}  // namespace adit::drivers
