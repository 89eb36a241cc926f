#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/velodyne.hpp"

namespace adit::drivers {
namespace {

std::string vlp16_yaml(double rot = 0.0) {
  std::string y = "lasers:\n";
  for (int i = 0; i < 16; ++i) {
    const int elevation = i % 2 == 0 ? -15 + i : i;  // -15, 1, -13, 3, ...
    y += "  - {laser_id: " + std::to_string(i) + ", rot_correction: " + std::to_string(rot) +
         ", vert_correction: " + fmt::format("{:.17g}", elevation * std::numbers::pi / 180.0) + ", dist_correction: 0.0}\n";
  }
  return y + "num_lasers: 16\ndistance_resolution: 0.002\n";
}

// A VLP-16 strongest-return packet: every block 0.2° apart from `azimuth0`,
// laser 1 (elevation +1°) of the first firing of each block at `raw` × 2 mm.
std::vector<std::uint8_t> vlp16_packet(int azimuth0, std::uint16_t raw, std::uint32_t us_past_hour) {
  std::vector<std::uint8_t> p(kVelodyneDataPacketSize, 0);
  for (int b = 0; b < 12; ++b) {
    std::uint8_t* block = p.data() + b * 100;
    block[0] = 0xFF;
    block[1] = 0xEE;
    const int az = (azimuth0 + 20 * b) % 36000;
    block[2] = static_cast<std::uint8_t>(az);
    block[3] = static_cast<std::uint8_t>(az >> 8);
    block[4 + 3 * 1] = static_cast<std::uint8_t>(raw);
    block[4 + 3 * 1 + 1] = static_cast<std::uint8_t>(raw >> 8);
    block[4 + 3 * 1 + 2] = 77;
  }
  for (int i = 0; i < 4; ++i) p[1200 + i] = static_cast<std::uint8_t>(us_past_hour >> (8 * i));
  p[1204] = 0x37;
  p[1205] = 0x22;
  return p;
}

TEST(VelodyneCalibration, ParsesLasersAndRejectsBadFilesWithTheirLine) {
  const VelodyneCalibration c = parse_velodyne_calibration(vlp16_yaml(), "vlp16.yaml");
  ASSERT_EQ(c.lasers.size(), 16u);
  EXPECT_NEAR(c.lasers[1].vert_correction, std::numbers::pi / 180.0, 1e-9);
  EXPECT_DOUBLE_EQ(c.distance_resolution_m, 0.002);

  try {
    parse_velodyne_calibration("lasers:\n  - {laser_id: 0, rot_correction: 0}\n", "bad.yaml");
    FAIL() << "accepted a laser without vert_correction";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "bad.yaml:2");
    EXPECT_EQ(e.key(), "lasers[0].vert_correction");
  }
  EXPECT_THROW(parse_velodyne_calibration("lasers: [", "x"), InputError);
  EXPECT_THROW(parse_velodyne_calibration("a: 1", "x"), InputError);
  EXPECT_THROW(parse_velodyne_calibration(vlp16_yaml() + "\n", "x").lasers.at(16), std::out_of_range);
  std::string twice = vlp16_yaml();
  twice.replace(twice.find("laser_id: 1,"), 12, "laser_id: 0,");
  EXPECT_THROW(parse_velodyne_calibration(twice, "x"), InputError);
  std::string degrees = vlp16_yaml();
  degrees.replace(degrees.find("vert_correction: "), 17, "vert_correction: 15");
  EXPECT_THROW(parse_velodyne_calibration(degrees, "x"), InputError);
  std::string count = vlp16_yaml();
  count.replace(count.find("num_lasers: 16"), 14, "num_lasers: 32");
  EXPECT_THROW(parse_velodyne_calibration(count, "x"), InputError);
  // A calibration of the wrong size for the model.
  EXPECT_THROW(VelodyneDecoder(VelodyneModel::vlp32c, parse_velodyne_calibration(vlp16_yaml(), "x")), InputError);
}

TEST(VelodyneDecoder, DecodesGeometryAndFiringTimes) {
  VelodyneDecoder decoder(VelodyneModel::vlp16, parse_velodyne_calibration(vlp16_yaml(), "x"));
  // 10 m at azimuth 90° (clockwise: to the right), elevation +1°.
  const auto packet = vlp16_packet(9000, 5000, 1'000'000);
  const std::int64_t host = 3'600'000'000'000 * 100 + 1'000'000'000;  // 100 h + 1 s
  const DecodedPacket d = decoder.decode(packet, host);
  ASSERT_EQ(d.status, PacketStatus::ok);
  ASSERT_EQ(d.points.size(), 12u);
  const DecodedPoint& p = d.points[0];
  EXPECT_NEAR(p.point.x, 0.0F, 1e-4);
  EXPECT_NEAR(p.point.y, -10.0F * std::cos(std::numbers::pi_v<float> / 180.0F), 1e-4);
  EXPECT_NEAR(p.point.z, 10.0F * std::sin(std::numbers::pi_v<float> / 180.0F), 1e-4);
  EXPECT_FLOAT_EQ(p.point.range_m, 10.0F);
  EXPECT_FLOAT_EQ(p.point.intensity, 77.0F);
  EXPECT_EQ(p.point.ring, 8);  // +1° is the 9th lowest of -15..15
  EXPECT_EQ(d.sensor_time_ns, host);
  // Laser 1 fires 2.304 µs into the sequence; block b starts b × 110.592 µs after the packet.
  EXPECT_EQ(p.sensor_time_ns, host + 2'304);
  EXPECT_EQ(d.points[5].sensor_time_ns, host + 5 * 110'592 + 2'304);
  // Its azimuth: the block's plus 2.304/110.592 of the 0.2° step, to 0.01°.
  EXPECT_FLOAT_EQ(d.points[0].azimuth_deg, 90.0F);
  EXPECT_NEAR(d.points[11].azimuth_deg, 92.2F, 0.006F);
}

TEST(VelodyneDecoder, ResolvesTheHourAndFollowsRollover) {
  VelodyneDecoder decoder(VelodyneModel::vlp16, parse_velodyne_calibration(vlp16_yaml(), "x"));
  const std::int64_t hour = 3'600'000'000'000;
  // Host just after 5:00:00, the sensor still at 4:59:59.9: the previous hour.
  const auto before = decoder.decode(vlp16_packet(0, 100, 3'599'900'000), 5 * hour + 50'000'000);
  EXPECT_EQ(before.sensor_time_ns, 4 * hour + 3'599'900'000'000);
  const auto after = decoder.decode(vlp16_packet(0, 100, 100'000), 5 * hour + 250'000'000);
  EXPECT_EQ(after.sensor_time_ns, 5 * hour + 100'000'000);
  EXPECT_EQ(decoder.clock().rollovers(), 1u);
}

TEST(VelodyneDecoder, CountsBadPacketsWithoutDecodingThem) {
  VelodyneDecoder decoder(VelodyneModel::vlp16, parse_velodyne_calibration(vlp16_yaml(), "x"));
  auto packet = vlp16_packet(0, 100, 1000);
  EXPECT_EQ(decoder.decode(std::span(packet).first(600), 0).status, PacketStatus::truncated);
  EXPECT_EQ(decoder.decode(std::vector<std::uint8_t>(1206, 0), 0).status, PacketStatus::foreign);
  EXPECT_EQ(decoder.decode(std::vector<std::uint8_t>(3000, 0xFF), 0).status, PacketStatus::foreign);
  auto bad_azimuth = packet;
  bad_azimuth[5 * 100 + 2] = 0xFF;
  bad_azimuth[5 * 100 + 3] = 0xFF;
  EXPECT_EQ(decoder.decode(bad_azimuth, 0).status, PacketStatus::malformed);
  auto bad_flag = packet;
  bad_flag[7 * 100 + 1] = 0xDD;
  EXPECT_EQ(decoder.decode(bad_flag, 0).status, PacketStatus::malformed);
  auto bad_time = packet;
  bad_time[1203] = 0xFF;  // ≥ one hour of µs
  EXPECT_EQ(decoder.decode(bad_time, 0).status, PacketStatus::malformed);
  auto bad_mode = packet;
  bad_mode[1204] = 0x40;
  EXPECT_EQ(decoder.decode(bad_mode, 0).status, PacketStatus::malformed);
}

TEST(VelodyneDecoder, DualReturnKeepsBothEchoesAndMergesIdenticalOnes) {
  VelodyneDecoder decoder(VelodyneModel::vlp16, parse_velodyne_calibration(vlp16_yaml(), "x"));
  auto packet = vlp16_packet(0, 1000, 1000);
  packet[1204] = 0x39;
  for (int b = 0; b < 12; b += 2) {  // pairs share the azimuth
    packet[(b + 1) * 100 + 2] = packet[b * 100 + 2];
    packet[(b + 1) * 100 + 3] = packet[b * 100 + 3];
  }
  packet[1 * 100 + 4 + 3] = 0xF4;  // pair 0: the strongest echo differs from the last one
  const DecodedPacket d = decoder.decode(packet, 0);
  ASSERT_EQ(d.status, PacketStatus::ok);
  ASSERT_EQ(d.points.size(), 7u);  // 6 pairs, one with two distinct echoes
  EXPECT_EQ(d.points[0].point.return_index, 1);  // last
  EXPECT_EQ(d.points[1].point.return_index, 0);  // strongest
  EXPECT_EQ(d.points[0].sensor_time_ns, d.points[1].sensor_time_ns);
  EXPECT_EQ(d.points[2].point.return_index, 0);  // identical echoes: one point
  EXPECT_EQ(d.points[2].sensor_time_ns - d.points[0].sensor_time_ns, 110'592);
}

TEST(VelodyneDecoder, TimesFiringsAfterAFieldOfViewGapByTheRotationRate) {
  VelodyneDecoder decoder(VelodyneModel::vlp16, parse_velodyne_calibration(vlp16_yaml(), "x"));
  // Blocks 0..5 at 90.0°, 90.2°, ... then the sensor skips to 270.0° (a limited field of view).
  auto packet = vlp16_packet(9000, 5000, 1000);
  for (int b = 6; b < 12; ++b) {
    const int az = 27000 + 20 * (b - 6);
    packet[b * 100 + 2] = static_cast<std::uint8_t>(az);
    packet[b * 100 + 3] = static_cast<std::uint8_t>(az >> 8);
  }
  const DecodedPacket d = decoder.decode(packet, 0);
  ASSERT_EQ(d.status, PacketStatus::ok);
  EXPECT_EQ(decoder.fov_gaps(), 1u);
  // 0.2° per 110.592 µs: the 179.0° skipped beyond the usual step took 895 group periods.
  const std::int64_t expected = 6 * 110'592 + (17'900 - 20) * 110'592 / 20;
  EXPECT_EQ(d.points[6].sensor_time_ns - d.points[0].sensor_time_ns, expected);
  // Firings before the gap are interpolated with the usual step, not the jump.
  EXPECT_NEAR(d.points[5].azimuth_deg, 91.0F, 0.01F);
  EXPECT_NEAR(d.points[6].azimuth_deg, 270.0F, 0.01F);
}

TEST(VelodyneModels, DetectsModelsAndRates) {
  auto packet = vlp16_packet(0, 0, 0);
  EXPECT_EQ(velodyne_model_from_packet(packet), VelodyneModel::vlp16);
  packet[1205] = 0x28;
  EXPECT_EQ(velodyne_model_from_packet(packet), VelodyneModel::vlp32c);
  packet[1205] = 0xA1;
  EXPECT_EQ(velodyne_model_from_packet(packet), VelodyneModel::vls128);
  packet[1205] = 0x77;
  EXPECT_FALSE(velodyne_model_from_packet(packet).has_value());
  EXPECT_EQ(velodyne_model_from_name("hdl-32e"), VelodyneModel::hdl32e);
  EXPECT_EQ(velodyne_model_from_name("VLS128"), VelodyneModel::vls128);
  EXPECT_FALSE(velodyne_model_from_name("HDL-64E").has_value());
  // Manuals: VLP-16 754 packets/s single, 1508 dual; HDL-32E 1808; VLP-32C 1507; VLS-128 6254.
  EXPECT_NEAR(1e9 / velodyne_packet_period_ns(VelodyneModel::vlp16, VelodyneReturnMode::strongest), 753.5, 1);
  EXPECT_NEAR(1e9 / velodyne_packet_period_ns(VelodyneModel::vlp16, VelodyneReturnMode::dual), 1507.0, 1);
  EXPECT_NEAR(1e9 / velodyne_packet_period_ns(VelodyneModel::hdl32e, VelodyneReturnMode::strongest), 1808.4, 1);
  EXPECT_NEAR(1e9 / velodyne_packet_period_ns(VelodyneModel::vlp32c, VelodyneReturnMode::strongest), 1507.0, 1);
  EXPECT_NEAR(1e9 / velodyne_packet_period_ns(VelodyneModel::vls128, VelodyneReturnMode::strongest), 6254.0, 1);
}

}  // namespace
}  // namespace adit::drivers
