// VLS-128 cross-checked field by field against the layout two independent
// decoders document, since no real VLS-128 capture is public (none found:
// docs/LIDAR.md). The packets are written here from the table below, not from
// the decoder's model table.
//
//  field                    | VLS-128 manual 63-9483 §9      | ROS velodyne rawdata   | nebula vls_128.hpp
//  -------------------------+--------------------------------+------------------------+---------------------
//  block flag = bank        | FFEE/FFDD/FFCC/FFBB: lasers    | VLS128_BANK_1..4       | BANK_1..4, bank_origin
//                           | 0-31/32-63/64-95/96-127        | 0xeeff..0xbbff (LE)    | 0/32/64/96
//  distance unit            | 4 mm (§9.3.1.3)                | VLS128_DISTANCE_       | distance_resolution_m
//                           |                                | RESOLUTION 0.004       | 0.004
//  single return            | 12 blocks = 3 sequences x 4    | next azimuth: block+1  | same
//  dual return              | blocks 0-7 pairs, 8-11 padding | BLOCKS - 4*dual        | getNumPaddingBlocks 4
//  firing group of laser l  | l/8 + l/64 (§9.5)              | (l/8 + l/8/8) slots    | i + i/8
//  time of laser l, seq k   | stamp + 53.3 k + 2.665 group   |  -                     | offset_packet_time
//                           |   - 8.7 µs                     |                        | 8.7 µs
//  product byte             | 0x63 (table 9-2)               | VLS128_MODEL_ID 161    |  -
//                           |                                | (0xA1)                 |
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "adit/drivers/lidar/velodyne.hpp"

namespace adit::drivers {
namespace {

constexpr int kLasers = 128;

struct Vls128Doc {
  std::array<std::uint8_t, 4> bank_flag_second_byte{0xEE, 0xDD, 0xCC, 0xBB};  // first byte 0xFF
  double unit_m = 0.004;
  double sequence_us = 53.3;
  double group_us = 2.665;
  double stamp_lead_us = 8.7;
  std::size_t dual_padding_blocks = 4;
};
constexpr Vls128Doc kDoc{};

double elevation_rad(int laser) { return (laser % 64 - 32) * 0.25 * std::numbers::pi / 180.0; }

VelodyneCalibration calibration(double distance_resolution) {
  VelodyneCalibration c;
  c.source = "synthetic VLS-128";
  c.distance_resolution_m = distance_resolution;
  for (int l = 0; l < kLasers; ++l) {
    VelodyneLaser laser;
    laser.laser_id = l;
    laser.vert_correction = elevation_rad(l);
    c.lasers.push_back(laser);
  }
  return c;
}

// Raw distance of laser l in sequence k.
std::uint16_t raw_distance(int sequence, int laser) { return static_cast<std::uint16_t>(2000 + 300 * sequence + laser); }

// Single return: sequence k in blocks 4k..4k+3, bank b in block 4k+b, each block its azimuth.
std::vector<std::uint8_t> single_packet(std::uint32_t us_past_hour, int azimuth0, int step, std::uint8_t product) {
  std::vector<std::uint8_t> p(kVelodyneDataPacketSize, 0);
  for (int block = 0; block < 12; ++block) {
    const int sequence = block / 4;
    const int bank = block % 4;
    std::uint8_t* b = p.data() + block * 100;
    b[0] = 0xFF;
    b[1] = kDoc.bank_flag_second_byte[static_cast<std::size_t>(bank)];
    const int az = (azimuth0 + sequence * step) % 36000;
    b[2] = static_cast<std::uint8_t>(az);
    b[3] = static_cast<std::uint8_t>(az >> 8);
    for (int c = 0; c < 32; ++c) {
      const std::uint16_t d = raw_distance(sequence, bank * 32 + c);
      b[4 + 3 * c] = static_cast<std::uint8_t>(d);
      b[5 + 3 * c] = static_cast<std::uint8_t>(d >> 8);
      b[6 + 3 * c] = static_cast<std::uint8_t>(bank * 32 + c);
    }
  }
  for (int i = 0; i < 4; ++i) p[1200 + i] = static_cast<std::uint8_t>(us_past_hour >> (8 * i));
  p[1204] = 0x37;
  p[1205] = product;
  return p;
}

TEST(VelodyneVls128Layout, SingleReturnBanksUnitAndTimesFollowTheDocumentedLayout) {
  // A calibration saying 2 mm (a VLP-16 default) must not change the VLS-128's 4 mm unit.
  VelodyneDecoder decoder(VelodyneModel::vls128, calibration(0.002));
  const std::uint32_t stamp_us = 1'000'000;
  const std::int64_t host = 3'600'000'000'000LL * 3 + 1'000'000'000LL;  // 3 h + 1 s: the packet's hour
  const DecodedPacket d = decoder.decode(single_packet(stamp_us, 1000, 20, 0xA1), host);
  ASSERT_EQ(d.status, PacketStatus::ok);
  ASSERT_EQ(d.points.size(), 3u * kLasers);
  const std::int64_t stamp_ns = host;
  EXPECT_EQ(d.sensor_time_ns, stamp_ns - 8'700);
  for (std::size_t i = 0; i < d.points.size(); ++i) {
    const int sequence = static_cast<int>(i) / kLasers;
    const int laser = static_cast<int>(i) % kLasers;
    const DecodedPoint& p = d.points[i];
    SCOPED_TRACE(testing::Message() << "sequence " << sequence << " laser " << laser);
    const double range = raw_distance(sequence, laser) * kDoc.unit_m;
    EXPECT_NEAR(p.point.range_m, range, 1e-4);
    EXPECT_NEAR(p.point.z, range * std::sin(elevation_rad(laser)), 1e-4);
    EXPECT_FLOAT_EQ(p.point.intensity, static_cast<float>(laser));
    const int group = laser / 8 + laser / 64;
    const double t_us = kDoc.sequence_us * sequence + kDoc.group_us * group - kDoc.stamp_lead_us;
    EXPECT_EQ(p.sensor_time_ns, stamp_ns + std::llround(t_us * 1000.0));
    // Precision azimuth: the sequence's block azimuth plus the share of the step elapsed at the firing.
    const double az = 10.0 + 0.2 * sequence + 0.2 * (group * kDoc.group_us) / kDoc.sequence_us;
    EXPECT_NEAR(p.azimuth_deg, az, 0.0051);
  }
  // The last firing group of a sequence fires 16 slots after the first (one idle slot after group 8).
  EXPECT_EQ(d.points[127].sensor_time_ns - d.points[0].sensor_time_ns, 16 * 2'665);
  EXPECT_EQ(decoder.model_mismatches(), 0u);
}

TEST(VelodyneVls128Layout, BothProductBytesAreRecognised) {
  EXPECT_EQ(velodyne_model_from_packet(single_packet(0, 0, 20, 0xA1)), VelodyneModel::vls128);
  EXPECT_EQ(velodyne_model_from_packet(single_packet(0, 0, 20, 0x63)), VelodyneModel::vls128);
  VelodyneDecoder decoder(VelodyneModel::vls128, calibration(0.0));
  ASSERT_EQ(decoder.decode(single_packet(0, 0, 20, 0x63), 0).status, PacketStatus::ok);
  EXPECT_EQ(decoder.model_mismatches(), 0u);
  EXPECT_EQ(velodyne_packet_period_ns(VelodyneModel::vls128, VelodyneReturnMode::strongest), 3 * 53'300);
  EXPECT_EQ(velodyne_packet_period_ns(VelodyneModel::vls128, VelodyneReturnMode::dual), 53'300);
}

TEST(VelodyneVls128Layout, BanksOutOfOrderAreMalformedNotMisplaced) {
  VelodyneDecoder decoder(VelodyneModel::vls128, calibration(0.0));
  auto p = single_packet(0, 0, 20, 0xA1);
  p[1 * 100 + 1] = 0xCC;  // block 1 claims bank 3
  EXPECT_EQ(decoder.decode(p, 0).status, PacketStatus::malformed);
  auto q = single_packet(0, 0, 20, 0xA1);
  q[0] = 0x00;  // not a Velodyne block at all
  EXPECT_EQ(decoder.decode(q, 0).status, PacketStatus::foreign);
}

TEST(VelodyneVls128Layout, DualPacketsLeaveTheDocumentedPaddingBlocksUnread) {
  VelodyneDecoder decoder(VelodyneModel::vls128, calibration(0.0));
  std::vector<std::uint8_t> p(kVelodyneDataPacketSize, 0);
  for (int block = 0; block < 8; ++block) {
    std::uint8_t* b = p.data() + block * 100;
    b[0] = 0xFF;
    b[1] = kDoc.bank_flag_second_byte[static_cast<std::size_t>(block / 2)];
    for (int c = 0; c < 32; ++c) {
      const std::uint16_t d = static_cast<std::uint16_t>(block % 2 == 0 ? 5000 + c : 1000 + c);
      b[4 + 3 * c] = static_cast<std::uint8_t>(d);
      b[5 + 3 * c] = static_cast<std::uint8_t>(d >> 8);
      b[6 + 3 * c] = 9;
    }
  }
  // Padding: anything, even bytes that look like blocks.
  for (std::size_t i = 800; i < 1200; ++i) p[i] = 0xAB;
  p[1204] = 0x39;
  p[1205] = 0xA1;
  const DecodedPacket d = decoder.decode(p, 0);
  ASSERT_EQ(d.status, PacketStatus::ok);
  EXPECT_EQ(d.points.size(), 2u * kLasers);
  EXPECT_EQ(kDoc.dual_padding_blocks, 12u - 8u);
  for (const DecodedPoint& point : d.points) {
    EXPECT_TRUE(point.point.range_m < 5032 * kDoc.unit_m + 1e-3) << point.point.range_m;
  }
}

}  // namespace
}  // namespace adit::drivers
