#include "adit/drivers/lidar/scan_assembler.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace adit::drivers {
namespace {

// A synthetic sensor: 10 packets per revolution, 4 firings of 9° per packet,
// 1 µs between firings, packets 4 µs apart.
constexpr int kPointsPerPacket = 4;
constexpr std::int64_t kFiringNs = 1000;
constexpr std::int64_t kPacketNs = kFiringNs * kPointsPerPacket;

struct FakeSensor {
  std::vector<DecodedPoint> storage = std::vector<DecodedPoint>(kPointsPerPacket);
  bool with_sequence = true;

  // Packet n starts at azimuth start_deg + 36·n.
  DecodedPacket packet(std::uint32_t n, float start_deg = 0.0F) {
    for (int i = 0; i < kPointsPerPacket; ++i) {
      DecodedPoint& p = storage[i];
      const int firing = static_cast<int>(n) * kPointsPerPacket + i;
      p.azimuth_deg = std::fmod(start_deg + 9.0F * static_cast<float>(firing), 360.0F);
      p.sensor_time_ns = 1'000'000 + firing * kFiringNs;
      p.point.ring = static_cast<std::uint16_t>(i);
      p.point.x = static_cast<float>(firing);
    }
    DecodedPacket out;
    out.status = PacketStatus::ok;
    out.sensor_time_ns = storage[0].sensor_time_ns;
    if (with_sequence) out.sequence = n;
    out.points = storage;
    return out;
  }
};

ScanAssemblerConfig config(float cut = 0.0F) {
  ScanAssemblerConfig c;
  c.cut_azimuth_deg = cut;
  c.max_points_per_scan = 100;
  c.packet_period_ns = kPacketNs;
  return c;
}

TEST(ScanAssembler, CutsAtTheAzimuthAndFillsTimeOffsets) {
  ScanAssembler assembler(config(90.0F));
  FakeSensor sensor;
  std::vector<LidarScan> scans;
  for (std::uint32_t n = 0; n < 35; ++n) {
    if (LidarScan* scan = assembler.add(sensor.packet(n))) scans.push_back(*scan);
  }
  // 140 firings; those at 90° are firings 10, 50, 90, 130: four cuts, the first scan partial.
  ASSERT_EQ(scans.size(), 4u);
  EXPECT_FALSE(scans[0].stats.complete);
  EXPECT_EQ(scans[0].points.size(), 10u);
  for (std::size_t i = 1; i < scans.size(); ++i) {
    const LidarScan& s = scans[i];
    EXPECT_TRUE(s.stats.complete);
    ASSERT_EQ(s.points.size(), 40u);
    EXPECT_EQ(s.points.front().x, static_cast<float>(10 + 40 * (i - 1)));
    EXPECT_EQ(s.sensor_start_time_ns, 1'000'000 + (10 + 40 * static_cast<std::int64_t>(i - 1)) * kFiringNs);
    for (std::size_t k = 0; k < s.points.size(); ++k) EXPECT_EQ(s.points[k].time_offset_ns, k * kFiringNs);
    // A packet split by the cut counts in both scans.
    EXPECT_EQ(s.stats.packets, 11u);
    EXPECT_EQ(s.stats.missing_packets, 0u);
  }
  LidarScan* rest = assembler.flush();
  ASSERT_NE(rest, nullptr);
  EXPECT_FALSE(rest->stats.complete);
  EXPECT_EQ(rest->points.size(), 10u);
  EXPECT_EQ(assembler.totals().scans, 5u);
  EXPECT_EQ(assembler.totals().complete_scans, 3u);
}

void run_with_loss(bool with_sequence) {
  ScanAssembler assembler(config());
  FakeSensor sensor;
  sensor.with_sequence = with_sequence;
  std::vector<LidarScan> scans;
  auto feed = [&](std::uint32_t n) {
    if (LidarScan* scan = assembler.add(sensor.packet(n))) scans.push_back(*scan);
  };
  for (std::uint32_t n = 0; n < 12; ++n) feed(n);  // scan 1 holds packets 10..19
  feed(12);
  feed(12);  // duplicate
  feed(15);  // 13, 14 lost
  feed(13);  // late
  for (std::uint32_t n = 16; n < 31; ++n) feed(n);
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_FALSE(scans[0].stats.complete);  // began mid-stream
  EXPECT_TRUE(scans[2].stats.complete);
  const ScanStats& damaged = scans[1].stats;
  EXPECT_FALSE(damaged.complete);
  EXPECT_EQ(damaged.missing_packets, 2u);
  EXPECT_EQ(damaged.duplicate_packets, 1u);
  EXPECT_EQ(damaged.out_of_order_packets, 1u);
  EXPECT_EQ(damaged.packets, 8u);
  EXPECT_EQ(scans[1].points.size(), 32u);
  EXPECT_EQ(assembler.totals().missing_packets, 2u);
  EXPECT_EQ(assembler.totals().duplicate_packets, 1u);
  EXPECT_EQ(assembler.totals().out_of_order_packets, 1u);
}

TEST(ScanAssembler, CountsLossBySequence) { run_with_loss(true); }
TEST(ScanAssembler, CountsLossByPacketTime) { run_with_loss(false); }

TEST(ScanAssembler, NeverWaitsAndCutsEvenWhenTheCutPacketIsLost) {
  ScanAssembler assembler(config());
  FakeSensor sensor;
  int emitted = 0;
  for (std::uint32_t n = 0; n < 30; ++n) {
    if (n == 10 || n == 20) continue;  // the packets holding 0° are lost
    if (assembler.add(sensor.packet(n)) != nullptr) {
      ++emitted;
      EXPECT_TRUE(n == 11 || n == 21) << n;  // the first packet after the loss cuts
    }
  }
  EXPECT_EQ(emitted, 2);
  EXPECT_EQ(assembler.totals().complete_scans, 0u);
  EXPECT_EQ(assembler.totals().missing_packets, 2u);
}

TEST(ScanAssembler, JitterBackAcrossTheCutDoesNotCutTwice) {
  ScanAssembler assembler(config());
  std::vector<DecodedPoint> pts(6);
  const float az[] = {350.0F, 359.5F, 0.2F, 359.8F, 0.5F, 1.0F};
  for (int i = 0; i < 6; ++i) {
    pts[i].azimuth_deg = az[i];
    pts[i].sensor_time_ns = i;
  }
  // Arm the assembler with a half revolution first.
  std::vector<DecodedPoint> half(1);
  half[0].azimuth_deg = 180.0F;
  DecodedPacket first{PacketStatus::ok, 0, 0u, half};
  EXPECT_EQ(assembler.add(first), nullptr);
  DecodedPacket p{PacketStatus::ok, 0, 1u, pts};
  LidarScan* scan = assembler.add(p);
  ASSERT_NE(scan, nullptr);
  EXPECT_EQ(scan->points.size(), 3u);
  EXPECT_EQ(assembler.flush()->points.size(), 4u);
}

TEST(ScanAssembler, CutsWhereAFieldOfViewGapJumpsOverTheCut) {
  // A sensor sending only 270°..90° (cut at 180°): the firings jump from 89° to 271°.
  ScanAssemblerConfig c = config(180.0F);
  ScanAssembler assembler(c);
  const float az[] = {300.0F, 10.0F, 60.0F, 89.0F, 271.0F, 330.0F, 20.0F, 89.5F, 270.5F};
  std::vector<DecodedPoint> pts(std::size(az));
  for (std::size_t i = 0; i < pts.size(); ++i) {
    pts[i].azimuth_deg = az[i];
    pts[i].sensor_time_ns = static_cast<std::int64_t>(i) * 1000;
  }
  std::vector<std::size_t> sizes;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const DecodedPacket p{PacketStatus::ok, pts[i].sensor_time_ns, static_cast<std::uint32_t>(i), std::span(pts).subspan(i, 1)};
    if (LidarScan* scan = assembler.add(p)) sizes.push_back(scan->points.size());
  }
  ASSERT_EQ(sizes.size(), 2u);
  EXPECT_EQ(sizes[0], 4u);  // 300 … 89
  EXPECT_EQ(sizes[1], 4u);  // 271 … 89.5
  EXPECT_EQ(assembler.totals().complete_scans, 1u);
}

TEST(ScanAssembler, DropsPointsBeyondCapacityAndIgnoresBadPackets) {
  ScanAssemblerConfig c = config();
  c.max_points_per_scan = 6;
  ScanAssembler assembler(c);
  FakeSensor sensor;
  assembler.add(sensor.packet(0));
  assembler.add(sensor.packet(1));
  DecodedPacket bad = sensor.packet(2);
  bad.status = PacketStatus::malformed;
  assembler.add(bad);
  EXPECT_EQ(assembler.totals().dropped_points, 2u);
  EXPECT_EQ(assembler.totals().packets, 2u);
  EXPECT_EQ(assembler.flush()->points.size(), 6u);
}

}  // namespace
}  // namespace adit::drivers
