// The Ouster encoder's LEGACY packets and metadata JSON, read back by the
// project's own parser and decoder.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "adit/drivers/lidar/ouster_decoder.hpp"
#include "adit/drivers/lidar/ouster_encoder.hpp"

namespace adit::drivers {
namespace {

TEST(OusterEncoder, NominalMetadataRoundTripsThroughTheParser) {
  const OusterMetadata m = ouster_os1_64_nominal_metadata();
  const OusterMetadata back = parse_ouster_metadata(format_ouster_metadata(m), "nominal.json");
  EXPECT_TRUE(back.legacy_layout);
  EXPECT_EQ(back.prod_line, "OS-1-64");
  EXPECT_EQ(back.lidar_mode, "1024x10");
  EXPECT_EQ(back.frame_rate_hz, 10);
  EXPECT_EQ(back.columns_per_frame, 1024);
  EXPECT_EQ(back.columns_per_packet, 16);
  EXPECT_EQ(back.pixels_per_column, 64);
  EXPECT_EQ(back.lidar_profile, OusterProfile::legacy);
  EXPECT_EQ(back.beam_altitude_deg, m.beam_altitude_deg);
  EXPECT_EQ(back.beam_azimuth_deg, m.beam_azimuth_deg);
  EXPECT_EQ(back.pixel_shift_by_row, m.pixel_shift_by_row);
  EXPECT_EQ(back.beam_to_lidar, m.beam_to_lidar);
  EXPECT_EQ(back.lidar_to_sensor, m.lidar_to_sensor);
  EXPECT_EQ(back.imu_to_sensor, m.imu_to_sensor);
  EXPECT_DOUBLE_EQ(back.lidar_origin_to_beam_origin_mm, 12.163);
  EXPECT_EQ(back.column_window, (std::array<int, 2>{0, 1023}));
  EXPECT_EQ(back.udp_port_lidar, 7502);
  EXPECT_EQ(back.udp_port_imu, 7503);
  EXPECT_EQ(OusterPacketLayout::of(back).packet_bytes, 12608U);
}

TEST(OusterEncoder, LegacyPacketDecodesToItsFields) {
  const OusterMetadata m = ouster_os1_64_nominal_metadata();
  const OusterPacketLayout layout = OusterPacketLayout::of(m);
  std::vector<std::uint8_t> bytes(layout.packet_bytes, 0xAA);
  OusterPacketEncoder e(layout, bytes);
  EXPECT_EQ(bytes[0], 0);  // cleared
  e.frame_id(321);
  for (int c = 0; c < 16; ++c) {
    const auto mid = static_cast<std::uint16_t>(512 + c);
    e.column_header(c, 5'000'000'000ULL + 97'656ULL * c, mid).encoder_count(c, mid * 88U);
  }
  e.pixel(3, 10, 0xFFFFF, 200, 1234, 55);  // the 20-bit range field's largest value
  e.pixel(15, 63, 2500, 7, 8, 9);

  const OusterColumnHeader h = read_column_header(layout, layout.column(bytes.data(), 3));
  EXPECT_EQ(h.timestamp_ns, 5'000'000'000ULL + 3 * 97'656ULL);
  EXPECT_EQ(h.measurement_id, 515);
  EXPECT_EQ(h.frame_id, 321);
  EXPECT_EQ(h.encoder_count, 515U * 88U);
  EXPECT_TRUE(h.valid);
  const OusterReturn r = read_return(OusterProfile::legacy, layout.pixel(layout.column(bytes.data(), 3), 10), 0);
  EXPECT_EQ(r.range_mm, 0xFFFFFU);
  EXPECT_EQ(r.reflectivity, 200);
  EXPECT_EQ(r.signal, 1234);
  EXPECT_EQ(r.near_ir, 55);

  OusterDecoder decoder(m);
  const DecodedPacket p = decoder.decode(e.bytes(), 0);
  ASSERT_EQ(p.status, PacketStatus::ok);
  ASSERT_EQ(p.points.size(), 2U);
  EXPECT_EQ(p.sequence, 321U * 64U + 32U);
  EXPECT_EQ(p.sensor_time_ns, 5'000'000'000LL);
  EXPECT_EQ(p.points[1].sensor_time_ns, 5'000'000'000LL + 15 * 97'656LL);
  EXPECT_FLOAT_EQ(p.points[1].point.range_m, 2.5F);
  EXPECT_EQ(decoder.counters().invalid_columns, 0U);
}

TEST(OusterEncoder, RejectsABufferOfTheWrongSize) {
  const OusterPacketLayout layout = OusterPacketLayout::of(OusterProfile::legacy, 16, 64);
  std::vector<std::uint8_t> bytes(layout.packet_bytes - 1);
  EXPECT_ANY_THROW(OusterPacketEncoder(layout, bytes));
}

}  // namespace
}  // namespace adit::drivers
