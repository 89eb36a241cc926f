// Pandar QT128C2X (UDP protocol 3.2) on packets written here field by field
// from the layout two independent sources document, since no real QT128
// capture is public (none found: docs/LIDAR-HESAI-ROBOSENSE.md):
//   Hesai SDK 2.0, libhesai/UdpProtocol/udp_protocol_v3_2.h and udp3_2_parser.cc (BSD-3),
//   tier4/nebula, nebula_decoders_hesai/decoders/pandar_qt128.hpp (Apache-2.0).
//
//  offset | field                                  | SDK 2.0 v3_2          | nebula
//  -------+----------------------------------------+-----------------------+-------------------------
//  0      | 0xEE 0xFF, major 3, minor 2, 2 reserved| udp_parser.cc 3/2     | Header12B
//  6      | lasers 128, blocks 2, first-block ret., | HS_LIDAR_HEADER_QT_V2 | Header12B
//         | dist unit (mm), returns, flags         |                       |
//  12     | 2 x (azimuth u16, 128 x (dist u16,     | BODY_AZIMUTH,         | Block<Unit4B,128>
//         |   refl u8 [, confidence u8 if 0x10]))  | CHN_UNIT(_NO_CONF)    | (always 4 bytes)
//  +      | body CRC u32                           | BODY_CRC              | crc_body
//  +      | functional safety 17 (flag 0x04)       | FUNCTION_SAFETY       | FunctionalSafety
//  tail   | res[5], mode flag, res[3], az flag u16,| TAIL_QT_V2 (26 bytes) | TailQT128C2X
//         | working mode, return mode, motor u16,  |                       |
//         | date-time[6], timestamp u32, factory   |                       |
//  +26    | UDP sequence u32 (flag 0x01)           | TAIL_SEQ_NUM          | (ignored)
//  +      | tail CRC u32                           | TAIL_CRC              | (ignored)
//  +      | signature 32 (flag 0x08)               | CYBER_SECURITY        | (ignored)
// With every flag set (0x1D) the packet is 1127 bytes: the size of the real captures.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "adit/drivers/lidar/hesai.hpp"
#include "adit/drivers/lidar/registry.hpp"

namespace adit::drivers {
namespace {

constexpr int kLasers = 128;
constexpr int kBlocks = 2;
constexpr double kDeg = std::numbers::pi / 180.0;

struct Qt128Packet {
  std::uint8_t flags = 0x1D;  // sequence, functional safety, signature, confidence
  std::uint8_t return_mode = 0x37;
  std::uint8_t mode_flag = 1;
  std::uint8_t unit_mm = 4;
  std::uint8_t year = 124;  // 2024 as years since 1900
  std::uint32_t unix_seconds = 0;  // when non-zero, sent in place of the date (year byte 0)
  std::uint32_t micros = 250'000;
  std::uint16_t azimuth = 9000;
  std::uint32_t sequence = 4242;
  std::uint8_t major = 3, minor = 2;
};

std::size_t expected_size(std::uint8_t flags) {
  const std::size_t unit = (flags & 0x10) != 0 ? 4 : 3;
  return 12 + kBlocks * (2 + kLasers * unit) + 4 + ((flags & 0x04) != 0 ? 17 : 0) + 26 +
         ((flags & 0x01) != 0 ? 4 : 0) + 4 + ((flags & 0x08) != 0 ? 32 : 0);
}

std::uint16_t raw_distance(int block, int channel) { return static_cast<std::uint16_t>(1500 + 10 * block + channel); }

std::vector<std::uint8_t> qt128(const Qt128Packet& in) {
  std::vector<std::uint8_t> p;
  auto u8 = [&](unsigned v) { p.push_back(static_cast<std::uint8_t>(v)); };
  auto u16 = [&](unsigned v) { u8(v & 0xFF), u8(v >> 8); };
  auto u32 = [&](std::uint32_t v) { u16(v & 0xFFFF), u16(v >> 16); };
  auto zeros = [&](int n) { p.insert(p.end(), static_cast<std::size_t>(n), 0); };
  u8(0xEE), u8(0xFF), u8(in.major), u8(in.minor), zeros(2);                 // pre-header
  u8(kLasers), u8(kBlocks), u8(0), u8(in.unit_mm), u8(1), u8(in.flags);    // header
  const bool dual = in.return_mode >= 0x39;
  for (int b = 0; b < kBlocks; ++b) {
    u16(dual ? in.azimuth : in.azimuth + 20 * b);
    for (int c = 0; c < kLasers; ++c) {
      u16(raw_distance(b, c));
      u8(c);  // reflectivity
      if ((in.flags & 0x10) != 0) u8(200);  // confidence
    }
  }
  u32(0xDEADBEEF);                                // body CRC (not checked)
  if ((in.flags & 0x04) != 0) zeros(17);          // functional safety
  zeros(5), u8(in.mode_flag), zeros(3), u16(0), u8(0);  // reserved, mode flag, reserved, azimuth flag, working mode
  u8(in.return_mode), u16(600);                   // return mode, motor speed
  if (in.unix_seconds != 0) {
    u8(0), u8(0);
    for (int i = 3; i >= 0; --i) u8(in.unix_seconds >> (8 * i));
  } else {
    u8(in.year), u8(3), u8(14), u8(15), u8(9), u8(26);  // 2024-03-14 15:09:26
  }
  u32(in.micros), u8(0x42);                       // timestamp, factory
  if ((in.flags & 0x01) != 0) u32(in.sequence);
  u32(0xCAFEF00D);                                // tail CRC
  if ((in.flags & 0x08) != 0) zeros(32);          // signature
  return p;
}

HesaiAngleCorrection angles() {
  HesaiAngleCorrection a;
  for (int c = 0; c < kLasers; ++c) {
    a.elevation_deg.push_back(52.0F - 0.8F * static_cast<float>(c));
    a.azimuth_deg.push_back(c % 2 == 0 ? 1.5F : -1.5F);
  }
  return a;
}

constexpr std::int64_t kSecond2024 = 1710428966;  // 2024-03-14 15:09:26 UTC

// QT128C2X manual "Laser Firing Time" (nebula's loop tables): channel 1 fires 2.312 µs into
// loop 2 and not in loop 1; channel 33 fires 27.656 µs into loop 1 and not in loop 2.
TEST(HesaiQt128, FullPacketOf1127BytesDecodesFieldByField) {
  const Qt128Packet in;
  const auto p = qt128(in);
  ASSERT_EQ(p.size(), 1127u);
  ASSERT_EQ(p.size(), expected_size(in.flags));
  EXPECT_EQ(hesai_model_from_packet(p), HesaiModel::pandar_qt128);
  const auto a = angles();
  HesaiDecoder decoder(HesaiModel::pandar_qt128, a);
  const DecodedPacket d = decoder.decode(p, 0);
  ASSERT_EQ(d.status, PacketStatus::ok);
  ASSERT_EQ(d.points.size(), static_cast<std::size_t>(kBlocks * kLasers));
  ASSERT_TRUE(d.sequence);
  EXPECT_EQ(*d.sequence, in.sequence);
  EXPECT_FLOAT_EQ(decoder.last_packet_info().distance_unit_m, 0.004F);
  EXPECT_EQ(decoder.last_packet_info().motor_rpm, 600);
  const std::int64_t t0 = kSecond2024 * 1'000'000'000LL + in.micros * 1000LL;
  for (int b = 0; b < kBlocks; ++b) {
    for (int c = 0; c < kLasers; ++c) {
      const DecodedPoint& pt = d.points[static_cast<std::size_t>(b * kLasers + c)];
      SCOPED_TRACE(testing::Message() << "block " << b << " channel " << c);
      const double r = raw_distance(b, c) * 0.004;
      const double az = ((in.azimuth + 20 * b) * 0.01 + a.azimuth_deg[static_cast<std::size_t>(c)]) * kDeg;
      const double el = a.elevation_deg[static_cast<std::size_t>(c)] * kDeg;
      ASSERT_NEAR(pt.point.range_m, r, 1e-5);
      ASSERT_NEAR(pt.point.x, r * std::cos(el) * std::cos(az), 2e-4);
      ASSERT_NEAR(pt.point.y, -r * std::cos(el) * std::sin(az), 2e-4);
      ASSERT_NEAR(pt.point.z, r * std::sin(el), 2e-4);
      ASSERT_EQ(pt.point.intensity, static_cast<float>(c));
    }
  }
  // Mode flag 1, single return: block 0 fires loop 1, block 1 loop 2 (SDK: (flag + block + 1) % 2).
  // Blocks: 9 µs + 111.11 µs x (1 - block) after the stamp.
  EXPECT_EQ(d.points[32].sensor_time_ns - t0, 9000 + 111110 + 27656);           // block 0, channel 33, loop 1
  EXPECT_EQ(d.points[kLasers + 0].sensor_time_ns - t0, 9000 + 2312);           // block 1, channel 1, loop 2
}

TEST(HesaiQt128, ModeFlagZeroStartsWithLoopTwo) {
  Qt128Packet in;
  in.mode_flag = 0;
  HesaiDecoder decoder(HesaiModel::pandar_qt128, angles());
  const DecodedPacket d = decoder.decode(qt128(in), 0);
  ASSERT_EQ(d.status, PacketStatus::ok);
  const std::int64_t t0 = kSecond2024 * 1'000'000'000LL + in.micros * 1000LL;
  EXPECT_EQ(d.points[0].sensor_time_ns - t0, 9000 + 111110 + 2312);            // block 0, channel 1, loop 2
  EXPECT_EQ(d.points[kLasers + 32].sensor_time_ns - t0, 9000 + 27656);         // block 1, channel 33, loop 1
}

TEST(HesaiQt128, DualReturnBlocksShareOneFiringInTheFlaggedLoop) {
  Qt128Packet in;
  in.return_mode = 0x39;  // last + strongest
  in.mode_flag = 1;
  HesaiDecoder decoder(HesaiModel::pandar_qt128, angles());
  const DecodedPacket d = decoder.decode(qt128(in), 0);
  ASSERT_EQ(d.status, PacketStatus::ok);
  EXPECT_EQ(decoder.last_packet_info().returns, 2);
  const DecodedPoint& last = d.points[40];
  const DecodedPoint& strongest = d.points[kLasers + 40];
  EXPECT_EQ(last.sensor_time_ns, strongest.sensor_time_ns);
  EXPECT_EQ(last.point.return_index, 1);
  EXPECT_EQ(strongest.point.return_index, 0);
  const std::int64_t t0 = kSecond2024 * 1'000'000'000LL + in.micros * 1000LL;
  EXPECT_EQ(last.sensor_time_ns - t0, 9000 + 33992);  // channel 41 in loop 1
}

TEST(HesaiQt128, EveryFlagVariantHasItsOwnSizeAndDecodes) {
  HesaiDecoder decoder(HesaiModel::pandar_qt128, angles());
  for (const std::uint8_t flags : {0x00, 0x01, 0x05, 0x10, 0x11, 0x15, 0x1D, 0x19}) {
    SCOPED_TRACE(testing::Message() << "flags 0x" << std::hex << int{flags});
    Qt128Packet in;
    in.flags = flags;
    const auto p = qt128(in);
    ASSERT_EQ(p.size(), expected_size(flags));
    EXPECT_EQ(hesai_model_from_packet(p), HesaiModel::pandar_qt128);
    const DecodedPacket d = decoder.decode(p, 0);
    ASSERT_EQ(d.status, PacketStatus::ok);
    ASSERT_EQ(d.points.size(), static_cast<std::size_t>(kBlocks * kLasers));
    EXPECT_NEAR(d.points[kLasers + 77].point.range_m, raw_distance(1, 77) * 0.004, 1e-5);
    EXPECT_EQ(d.sequence.has_value(), (flags & 0x01) != 0);
    // One byte more or less than the flags announce is not this packet.
    auto longer = p;
    longer.push_back(0);
    EXPECT_EQ(decoder.decode(longer, 0).status, PacketStatus::malformed);
    EXPECT_EQ(decoder.decode(std::span(p.data(), p.size() - 1), 0).status, PacketStatus::truncated);
  }
}

TEST(HesaiQt128, TwoDigitYearsAndUnixSecondsAreTheSameTime) {
  HesaiDecoder decoder(HesaiModel::pandar_qt128, angles());
  Qt128Packet in;
  const auto t1900 = decoder.decode(qt128(in), 0).sensor_time_ns;
  in.year = 24;  // years since 2000
  const auto t2000 = decoder.decode(qt128(in), 0).sensor_time_ns;
  in.unix_seconds = static_cast<std::uint32_t>(kSecond2024);
  const auto tunix = decoder.decode(qt128(in), 0).sensor_time_ns;
  EXPECT_EQ(t1900, t2000);
  EXPECT_EQ(t1900, tunix);
}

TEST(HesaiQt128, OtherProtocolsWith128LasersAreForeign) {
  HesaiDecoder decoder(HesaiModel::pandar_qt128, angles());
  Qt128Packet p128e3x;  // Pandar128E3X speaks protocol 1.4 with 128 lasers x 2 blocks
  p128e3x.major = 1;
  p128e3x.minor = 4;
  EXPECT_EQ(decoder.decode(qt128(p128e3x), 0).status, PacketStatus::foreign);
  EXPECT_FALSE(hesai_model_from_packet(qt128(p128e3x)));
}

TEST(HesaiQt128, TheRegistryDetectsIt) {
  const DetectedLidar detected = detect_lidar(qt128(Qt128Packet{}), 2368);
  ASSERT_NE(detected.family, nullptr);
  EXPECT_EQ(detected.family->name, "hesai");
  EXPECT_EQ(detected.model, "PandarQT128");
}

}  // namespace
}  // namespace adit::drivers
