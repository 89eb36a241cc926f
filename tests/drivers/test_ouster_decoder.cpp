#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <random>

#include "adit/drivers/lidar/ouster_decoder.hpp"
#include "adit/drivers/lidar/ouster_encoder.hpp"

namespace adit::drivers {
namespace {

// A 4-beam, 1024-column sensor with simple geometry.
OusterMetadata simple_metadata(OusterProfile profile) {
  OusterMetadata m;
  m.prod_line = "OS-1-TEST";
  m.lidar_mode = "1024x10";
  m.beam_altitude_deg = {30.0, 10.0, -10.0, 0.0};
  m.beam_azimuth_deg = {0.0, 0.0, 0.0, 0.0};
  m.lidar_origin_to_beam_origin_mm = 0.0;
  m.beam_to_lidar = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  m.lidar_to_sensor = m.beam_to_lidar;
  m.columns_per_frame = 1024;
  m.columns_per_packet = 16;
  m.pixels_per_column = 4;
  m.pixel_shift_by_row = {0, 0, 0, 0};
  m.column_window = {0, 1023};
  m.lidar_profile = profile;
  return m;
}

TEST(OusterPacketLayout, SizesMatchTheFirmwareManual) {
  EXPECT_EQ(OusterPacketLayout::of(OusterProfile::legacy, 16, 32).packet_bytes, 6464U);
  EXPECT_EQ(OusterPacketLayout::of(OusterProfile::legacy, 16, 64).packet_bytes, 12608U);
  EXPECT_EQ(OusterPacketLayout::of(OusterProfile::rng15_rfl8_nir8, 16, 128).packet_bytes, 8448U);
  EXPECT_EQ(OusterPacketLayout::of(OusterProfile::rng19_rfl8_sig16_nir16, 16, 64).packet_bytes, 12544U);
  EXPECT_EQ(OusterPacketLayout::of(OusterProfile::rng19_rfl8_sig16_nir16_dual, 16, 128).packet_bytes, 33024U);
}

class OusterProfiles : public ::testing::TestWithParam<OusterProfile> {};

TEST_P(OusterProfiles, DecodesFieldsGeometryTimeAndSequence) {
  const OusterMetadata m = simple_metadata(GetParam());
  OusterDecoder decoder(m);
  std::vector<std::uint8_t> b_packet(OusterPacketLayout::of(m).packet_bytes);
  OusterPacketEncoder b(OusterPacketLayout::of(m), b_packet);
  b.frame_id(5);
  for (int c = 0; c < 16; ++c) b.column_header(c, 1'000'000 + 1000 * c, static_cast<std::uint16_t>(256 + c));
  // Column 0 (mid 256: a quarter turn), beam 3 (altitude 0) and beam 0 (30°).
  b.pixel(0, 3, 2000, 77, 300, 160).pixel(0, 0, 4000, 9, 20, 32);
  const DecodedPacket p = decoder.decode(b.bytes(), 0);
  ASSERT_EQ(p.status, PacketStatus::ok);
  ASSERT_EQ(p.points.size(), 2U);
  EXPECT_EQ(p.sequence, 5U * 64U + 16U);
  EXPECT_EQ(p.sensor_time_ns, 1'000'000);

  // Rows are visited top to bottom: beam 0 first.
  const DecodedPoint& up = p.points[0];
  const DecodedPoint& level = p.points[1];
  // θe = 2π(1 - 256/1024) = 3π/2: the lidar frame's -y axis.
  EXPECT_NEAR(level.point.x, 0.0F, 1e-6F);
  EXPECT_NEAR(level.point.y, -2.0F, 1e-6F);
  EXPECT_NEAR(level.point.z, 0.0F, 1e-6F);
  EXPECT_NEAR(up.point.y, -4.0F * std::cos(std::numbers::pi_v<float> / 6), 1e-5F);
  EXPECT_NEAR(up.point.z, 2.0F, 1e-5F);
  EXPECT_FLOAT_EQ(level.azimuth_deg, 90.0F);
  EXPECT_EQ(level.sensor_time_ns, 1'000'000);
  EXPECT_FLOAT_EQ(level.point.range_m, 2.0F);
  EXPECT_EQ(level.point.intensity, 77.0F);
  EXPECT_EQ(level.point.ring, 1);  // altitudes -10, 0, 10, 30: 0° is the second lowest
  EXPECT_EQ(up.point.ring, 3);
  EXPECT_EQ(level.point.near_ir, 160);
  if (GetParam() != OusterProfile::rng15_rfl8_nir8) {
    EXPECT_EQ(level.point.signal, 300);
  }
}

INSTANTIATE_TEST_SUITE_P(AllProfiles, OusterProfiles,
                         ::testing::Values(OusterProfile::legacy, OusterProfile::rng19_rfl8_sig16_nir16,
                                           OusterProfile::rng15_rfl8_nir8,
                                           OusterProfile::rng19_rfl8_sig16_nir16_dual));

TEST(OusterDecoder, DualProfileGivesTwoReturnsPerPixel) {
  const OusterMetadata m = simple_metadata(OusterProfile::rng19_rfl8_sig16_nir16_dual);
  OusterDecoder decoder(m);
  std::vector<std::uint8_t> b_packet(OusterPacketLayout::of(m).packet_bytes);
  OusterPacketEncoder b(OusterPacketLayout::of(m), b_packet);
  for (int c = 0; c < 16; ++c) b.column_header(c, 10, static_cast<std::uint16_t>(c));
  b.pixel(2, 1, 5000, 50, 400, 7);
  b.pixel_bytes(2, 1, 4, 7000, 3).pixel_bytes(2, 1, 7, 60, 1).pixel_bytes(2, 1, 10, 900, 2);  // second return
  const DecodedPacket p = decoder.decode(b.bytes(), 0);
  ASSERT_EQ(p.points.size(), 2U);
  EXPECT_EQ(p.points[0].point.return_index, 0);
  EXPECT_EQ(p.points[1].point.return_index, 1);
  EXPECT_FLOAT_EQ(p.points[1].point.range_m, 7.0F);
  EXPECT_EQ(p.points[1].point.intensity, 60.0F);
  EXPECT_EQ(p.points[1].point.signal, 900);
  EXPECT_EQ(p.points[1].point.near_ir, 7);  // shared by both returns
}

TEST(OusterDecoder, LowDataProfileAppliesMultipliers) {
  const auto px = std::array<std::uint8_t, 4>{0xFF, 0xFF, 200, 0xFF};
  const OusterReturn r = read_return(OusterProfile::rng15_rfl8_nir8, px.data(), 0);
  EXPECT_EQ(r.range_mm, 0x7FFFU * 8U);  // 15 bits of 8 mm
  EXPECT_EQ(r.flags, 1);
  EXPECT_EQ(r.reflectivity, 200);
  EXPECT_EQ(r.near_ir, 255 * 16);
}

TEST(OusterDecoder, SensorTransformAndBeamOriginFollowTheManual) {
  OusterMetadata m = simple_metadata(OusterProfile::legacy);
  m.lidar_origin_to_beam_origin_mm = 12.0;
  m.beam_to_lidar[3] = 12.0;
  m.lidar_to_sensor = {-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 36.18, 0, 0, 0, 1};
  OusterDecoder decoder(m);
  std::vector<std::uint8_t> b_packet(OusterPacketLayout::of(m).packet_bytes);
  OusterPacketEncoder b(OusterPacketLayout::of(m), b_packet);
  for (int c = 0; c < 16; ++c) b.column_header(c, 10, static_cast<std::uint16_t>(c));
  b.pixel(0, 0, 1000, 1, 1, 1);  // mid 0, altitude 30°
  const DecodedPacket p = decoder.decode(b.bytes(), 0);
  ASSERT_EQ(p.points.size(), 1U);
  const double phi = std::numbers::pi / 6;
  // Lidar frame: x = (r - n) cos φ + n, z = (r - n) sin φ; sensor: x -> -x, z + 36.18.
  EXPECT_NEAR(p.points[0].point.x, -((1000 - 12) * std::cos(phi) + 12) / 1000, 1e-6);
  EXPECT_NEAR(p.points[0].point.y, 0.0, 1e-6);
  EXPECT_NEAR(p.points[0].point.z, ((1000 - 12) * std::sin(phi) + 36.18) / 1000, 1e-6);
}

TEST(OusterDecoder, InvalidColumnsAndZeroRangesGiveNoPoints) {
  const OusterMetadata m = simple_metadata(OusterProfile::rng19_rfl8_sig16_nir16);
  OusterDecoder decoder(m);
  std::vector<std::uint8_t> b_packet(OusterPacketLayout::of(m).packet_bytes);
  OusterPacketEncoder b(OusterPacketLayout::of(m), b_packet);
  for (int c = 0; c < 16; ++c) b.column_header(c, 10, static_cast<std::uint16_t>(c), /*valid=*/c != 3);
  b.pixel(3, 0, 1000, 1, 1, 1).pixel(4, 0, 1000, 1, 1, 1);
  const DecodedPacket p = decoder.decode(b.bytes(), 0);
  EXPECT_EQ(p.status, PacketStatus::ok);
  EXPECT_EQ(p.points.size(), 1U);
  EXPECT_EQ(decoder.counters().invalid_columns, 1U);
}

TEST(OusterDecoder, RangeInMetresGivesBackTheExactMillimetres) {
  const OusterMetadata m = simple_metadata(OusterProfile::legacy);
  OusterDecoder decoder(m);
  std::mt19937 rng(7);
  for (int i = 0; i < 200; ++i) {
    std::vector<std::uint8_t> b_packet(OusterPacketLayout::of(m).packet_bytes);
    OusterPacketEncoder b(OusterPacketLayout::of(m), b_packet);
    for (int c = 0; c < 16; ++c) b.column_header(c, 10, static_cast<std::uint16_t>(c));
    const std::uint32_t mm = i == 0 ? 0xFFFFFU : (rng() & 0xFFFFFU) | 1U;  // up to the 20-bit maximum
    b.pixel(0, 0, mm, 1, 1, 1);
    const DecodedPacket p = decoder.decode(b.bytes(), 0);
    ASSERT_EQ(p.points.size(), 1U);
    EXPECT_EQ(static_cast<std::uint32_t>(std::lround(static_cast<double>(p.points[0].point.range_m) * 1000.0)), mm);
  }
}

TEST(OusterDecoder, ImuPacketsAreDecodedToSi) {
  OusterDecoder decoder(simple_metadata(OusterProfile::legacy));
  std::vector<std::uint8_t> imu(48, 0);
  const auto put_f32 = [&](std::size_t at, float v) {
    std::uint32_t u = 0;
    std::memcpy(&u, &v, 4);
    for (int i = 0; i < 4; ++i) imu[at + i] = static_cast<std::uint8_t>(u >> (8 * i));
  };
  imu[0] = 0x10;  // system time 16 ns
  imu[8] = 0x20;
  imu[16] = 0x30;
  put_f32(24, 0.0F);
  put_f32(28, 0.5F);
  put_f32(32, -1.0F);  // g
  put_f32(36, 90.0F);  // deg/s
  const DecodedPacket p = decoder.decode(imu, 0);
  EXPECT_EQ(p.status, PacketStatus::auxiliary);
  EXPECT_TRUE(p.points.empty());
  const OusterImuSample& s = decoder.last_imu();
  EXPECT_EQ(s.system_time_ns, 0x10U);
  EXPECT_EQ(s.accel_time_ns, 0x20U);
  EXPECT_EQ(s.gyro_time_ns, 0x30U);
  EXPECT_FLOAT_EQ(s.accel_mps2[1], 0.5F * 9.80665F);
  EXPECT_FLOAT_EQ(s.accel_mps2[2], -9.80665F);
  EXPECT_FLOAT_EQ(s.gyro_radps[0], std::numbers::pi_v<float> / 2);
  EXPECT_EQ(decoder.counters().imu_packets, 1U);
}

TEST(OusterDecoder, TruncatedForeignAndMalformedPacketsAreRejected) {
  const OusterMetadata m = simple_metadata(OusterProfile::rng19_rfl8_sig16_nir16);
  OusterDecoder decoder(m);
  std::vector<std::uint8_t> b_packet(OusterPacketLayout::of(m).packet_bytes);
  OusterPacketEncoder b(OusterPacketLayout::of(m), b_packet);
  for (int c = 0; c < 16; ++c) b.column_header(c, 10, static_cast<std::uint16_t>(c));
  const std::vector<std::uint8_t>& good = b_packet;

  std::vector<std::uint8_t> cut(good.begin(), good.end() - 1);
  EXPECT_EQ(decoder.decode(cut, 0).status, PacketStatus::truncated);
  std::vector<std::uint8_t> longer = good;
  longer.push_back(0);
  EXPECT_EQ(decoder.decode(longer, 0).status, PacketStatus::foreign);
  EXPECT_EQ(decoder.decode(std::vector<std::uint8_t>(1206, 0xFF), 0).status, PacketStatus::foreign);  // a Velodyne
  EXPECT_EQ(decoder.decode({}, 0).status, PacketStatus::foreign);
  std::vector<std::uint8_t> other_type = good;
  other_type[0] = 2;
  EXPECT_EQ(decoder.decode(other_type, 0).status, PacketStatus::foreign);

  std::vector<std::uint8_t> bad_packet(OusterPacketLayout::of(m).packet_bytes);
  OusterPacketEncoder bad(OusterPacketLayout::of(m), bad_packet);
  for (int c = 0; c < 16; ++c) bad.column_header(c, 10, 5000);  // beyond 1024 columns
  EXPECT_EQ(decoder.decode(bad.bytes(), 0).status, PacketStatus::malformed);
  EXPECT_EQ(decoder.counters().lidar_packets, 0U);
}

TEST(OusterDecoder, RandomBytesNeverCrashAndStayInBounds) {
  for (const auto profile : {OusterProfile::legacy, OusterProfile::rng15_rfl8_nir8,
                             OusterProfile::rng19_rfl8_sig16_nir16_dual}) {
    const OusterMetadata m = simple_metadata(profile);
    OusterDecoder decoder(m);
    const std::size_t size = OusterPacketLayout::of(m).packet_bytes;
    std::mt19937 rng(11);
    for (int i = 0; i < 300; ++i) {
      std::vector<std::uint8_t> bytes(i % 3 == 0 ? rng() % (2 * size) : size);
      for (auto& x : bytes) x = static_cast<std::uint8_t>(rng());
      if (!bytes.empty() && profile != OusterProfile::legacy && i % 2 == 0) bytes[0] = 1, bytes[1] = 0;
      const DecodedPacket p = decoder.decode(bytes, 0);
      EXPECT_LE(p.points.size(), decoder.max_points_per_packet());
      for (const auto& dp : p.points) {
        EXPECT_TRUE(std::isfinite(dp.point.x) && std::isfinite(dp.point.y) && std::isfinite(dp.point.z));
        EXPECT_LT(dp.azimuth_deg, 360.0F);
      }
    }
  }
}

}  // namespace
}  // namespace adit::drivers
