// Hesai and RoboSense decoders on synthetic packets built from the manuals'
// layouts (lidar_packet_builders.hpp): every Hesai model of the table, the
// angle-correction parsers, firing times, and bad input of every kind.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/hesai.hpp"
#include "adit/drivers/lidar/registry.hpp"
#include "adit/drivers/lidar/robosense.hpp"
#include "lidar_packet_builders.hpp"

namespace adit::drivers {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr std::int64_t kPacketSecond = 1673398923;  // 2023-01-11 01:02:03 UTC

HesaiAngleCorrection angles_for(int lasers) {
  HesaiAngleCorrection a;
  for (int c = 0; c < lasers; ++c) {
    a.elevation_deg.push_back(15.0F - 0.25F * static_cast<float>(c));  // descending, like XT32 files
    a.azimuth_deg.push_back(c % 2 == 0 ? 1.5F : -2.0F);
  }
  return a;
}

TEST(HesaiAngleCsv, ReadsBothHeaderStylesCrlfBomAndBlanks) {
  const auto xt = parse_hesai_angle_csv("\xEF\xBB\xBF" "Channel,Elevation,Azimuth\r\n1,14.97,0.08\r\n2,-1.5, -0.25 \r\n\r\n", "xt.csv");
  ASSERT_EQ(xt.elevation_deg.size(), 2u);
  EXPECT_FLOAT_EQ(xt.elevation_deg[1], -1.5F);
  EXPECT_FLOAT_EQ(xt.azimuth_deg[1], -0.25F);
  const auto qt = parse_hesai_angle_csv("Laser id,Elevation,Azimuth\n1,-52.121,8.736\n2,-49.785,8.314", "qt.csv");
  EXPECT_EQ(qt.elevation_deg.size(), 2u);
  EXPECT_FLOAT_EQ(qt.azimuth_deg[0], 8.736F);
}

TEST(HesaiAngleCsv, RejectsBadRowsNamingFileLineAndColumn) {
  const auto expect_error = [](const char* text, const char* where, const char* key) {
    try {
      parse_hesai_angle_csv(text, "cal.csv");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_EQ(e.where(), where) << text;
      EXPECT_EQ(e.key(), key) << text;
    }
  };
  expect_error("Channel,Elevation,Azimuth\n1,abc,0\n", "cal.csv:2", "elevation");
  expect_error("Channel,Elevation,Azimuth\n1,1,0\n3,1,0\n", "cal.csv:3", "id");
  expect_error("Channel,Elevation,Azimuth\n1,1\n", "cal.csv:2", "azimuth");
  expect_error("1,95,0\n", "cal.csv:1", "elevation");
  expect_error("1,5,0\nxyz,1,1\n", "cal.csv:2", "id");
  expect_error("Channel,Elevation,Azimuth\n", "cal.csv", "id");
  EXPECT_THROW(HesaiDecoder(HesaiModel::pandar_xt32, angles_for(16)), InputError);
}

TEST(HesaiModels, NamesRoundTrip) {
  for (const auto& layout : test::hesai_layouts()) {
    const auto model = hesai_model_from_name(layout.model);
    ASSERT_TRUE(model) << layout.model;
    EXPECT_EQ(hesai_model_name(*model), layout.model);
    EXPECT_EQ(hesai_laser_count(*model), layout.lasers);
  }
  EXPECT_EQ(hesai_model_from_name("pandarqt128c2x"), HesaiModel::pandar_qt128);
  EXPECT_FALSE(hesai_model_from_name("VLP-16"));
}

// Every model: positions from the packet fields and the calibration, time from the tail.
TEST(HesaiDecoder, DecodesEveryModelOfTheTable) {
  for (const auto& layout : test::hesai_layouts()) {
    SCOPED_TRACE(layout.model);
    const auto model = *hesai_model_from_name(layout.model);
    const auto angles = angles_for(layout.lasers);
    HesaiDecoder decoder(model, angles);
    EXPECT_EQ(decoder.max_points_per_packet(), static_cast<std::size_t>(layout.lasers * layout.blocks));
    test::HesaiContent content;
    const auto packet = test::hesai_packet(layout, content);
    const DecodedPacket out = decoder.decode(packet, 0);
    ASSERT_EQ(out.status, PacketStatus::ok);
    ASSERT_EQ(out.points.size(), static_cast<std::size_t>(layout.lasers * layout.blocks));
    const double unit = layout.framing == 2 ? 0.004 : 0.001 * content.dis_unit_mm;
    for (int b = 0; b < layout.blocks; ++b) {
      for (int c = 0; c < layout.lasers; c += 7) {
        const DecodedPoint& d = out.points[static_cast<std::size_t>(b * layout.lasers + c)];
        const double r = (1000 + c) * unit;
        const double az = ((content.first_azimuth + b * content.azimuth_step) * 0.01 + angles.azimuth_deg[c]) * kDeg;
        const double el = angles.elevation_deg[c] * kDeg;
        EXPECT_NEAR(d.point.x, r * std::cos(el) * std::cos(az), 1e-4);
        EXPECT_NEAR(d.point.y, -r * std::cos(el) * std::sin(az), 1e-4);
        EXPECT_NEAR(d.point.z, r * std::sin(el), 1e-4);
        EXPECT_NEAR(d.point.range_m, r, 1e-5);
        EXPECT_EQ(d.point.intensity, static_cast<float>(c));
        EXPECT_EQ(d.point.ring, layout.lasers - 1 - c);  // descending elevations: channel 0 is the top ring
        EXPECT_EQ(d.point.return_index, 0);
        EXPECT_FLOAT_EQ(d.azimuth_deg, static_cast<float>((content.first_azimuth + b * content.azimuth_step) * 0.01));
        // Firing within a quarter millisecond of the tail's time (the longest packet, QT64, spans 0.65 ms).
        const std::int64_t packet_ns = kPacketSecond * 1'000'000'000LL + content.micros * 1000LL;
        EXPECT_LT(std::abs(d.sensor_time_ns - packet_ns), 700'000) << "block " << b << " channel " << c;
      }
    }
    EXPECT_LE(out.sensor_time_ns, out.points.front().sensor_time_ns);
    if (layout.t_sequence >= 0) {
      EXPECT_EQ(out.sequence, content.sequence);
    }
    EXPECT_EQ(decoder.last_packet_info().returns, 1);
  }
}

// PandarXT32 manual timing: blocks 50 us apart ending 5.632 us after the tail time, channel i
// 0.368 + 1.512 i us into its block; both returns of a dual firing share their time.
TEST(HesaiDecoder, Xt32FiringTimesAndDualReturns) {
  const auto layout = test::hesai_layouts()[1];
  HesaiDecoder decoder(HesaiModel::pandar_xt32, angles_for(32));
  test::HesaiContent content;
  const std::int64_t t0 = kPacketSecond * 1'000'000'000LL + content.micros * 1000LL;
  auto out = decoder.decode(test::hesai_packet(layout, content), 0);
  ASSERT_EQ(out.status, PacketStatus::ok);
  EXPECT_EQ(out.points[7 * 32 + 0].sensor_time_ns - t0, 5632 + 368);
  EXPECT_EQ(out.points[0 * 32 + 31].sensor_time_ns - t0, 5632 - 7 * 50000 + 368 + 1512 * 31);

  content.return_mode = 0x3B;  // dual first + last, sent last-first by the XT series
  out = decoder.decode(test::hesai_packet(layout, content), 0);
  ASSERT_EQ(out.status, PacketStatus::ok);
  const DecodedPoint& even = out.points[2 * 32 + 5];
  const DecodedPoint& odd = out.points[3 * 32 + 5];
  EXPECT_EQ(even.sensor_time_ns, odd.sensor_time_ns);
  EXPECT_EQ(even.azimuth_deg, odd.azimuth_deg);
  EXPECT_EQ(even.point.return_index, 1);  // the last return comes first
  EXPECT_EQ(odd.point.return_index, 0);
  EXPECT_EQ(decoder.last_packet_info().returns, 2);
}

TEST(HesaiDecoder, ZeroDistanceIsNoPoint) {
  const auto layout = test::hesai_layouts()[3];
  HesaiDecoder decoder(HesaiModel::pandar_qt64, angles_for(64));
  auto packet = test::hesai_packet(layout);
  packet[12 + 2] = 0, packet[12 + 3] = 0;  // block 0, channel 0
  const auto out = decoder.decode(packet, 0);
  ASSERT_EQ(out.status, PacketStatus::ok);
  EXPECT_EQ(out.points.size(), 4u * 64 - 1);
}

TEST(HesaiDecoder, BadPacketsComeBackWithAStatusNeverACrash) {
  for (const auto& layout : test::hesai_layouts()) {
    SCOPED_TRACE(layout.model);
    HesaiDecoder decoder(*hesai_model_from_name(layout.model), angles_for(layout.lasers));
    const auto good = test::hesai_packet(layout);
    // Cut at every length: never ok, never a crash.
    for (std::size_t n = 0; n < good.size(); ++n) {
      const auto out = decoder.decode(std::span(good.data(), n), 0);
      EXPECT_NE(out.status, PacketStatus::ok) << n;
      EXPECT_TRUE(out.points.empty());
    }
    EXPECT_EQ(decoder.decode(std::span(good.data(), good.size() - 1), 0).status, PacketStatus::truncated);
    auto oversized = good;
    oversized.resize(good.size() + 64, 0);
    // Pandar40P has no header: past its largest size, a leading 0xFFEE proves nothing.
    EXPECT_EQ(decoder.decode(oversized, 0).status,
              layout.framing == 2 ? PacketStatus::foreign : PacketStatus::malformed);
    // Other models' packets are foreign.
    for (const auto& other : test::hesai_layouts()) {
      if (other.model == layout.model) continue;
      EXPECT_EQ(decoder.decode(test::hesai_packet(other), 0).status, PacketStatus::foreign) << other.model;
    }
    std::vector<std::uint8_t> velodyne(1206, 0);
    velodyne[0] = 0xFF, velodyne[1] = 0xEE;
    EXPECT_EQ(decoder.decode(velodyne, 0).status, PacketStatus::foreign);
    // Impossible content.
    test::HesaiContent bad_mode;
    bad_mode.return_mode = 0x99;
    EXPECT_EQ(decoder.decode(test::hesai_packet(layout, bad_mode), 0).status, PacketStatus::malformed);
    test::HesaiContent bad_date;
    bad_date.month = 13;
    EXPECT_EQ(decoder.decode(test::hesai_packet(layout, bad_date), 0).status, PacketStatus::malformed);
    test::HesaiContent bad_micros;
    bad_micros.micros = 1'000'000;
    EXPECT_EQ(decoder.decode(test::hesai_packet(layout, bad_micros), 0).status, PacketStatus::malformed);
    test::HesaiContent bad_azimuth;
    bad_azimuth.first_azimuth = 36000;
    bad_azimuth.azimuth_step = 0;
    EXPECT_EQ(decoder.decode(test::hesai_packet(layout, bad_azimuth), 0).status, PacketStatus::malformed);
    // Random bytes of every length up to the packet's, with and without our magic.
    std::mt19937 rng(7);
    for (int i = 0; i < 300; ++i) {
      std::vector<std::uint8_t> noise(rng() % (good.size() + 100));
      for (auto& byte : noise) byte = static_cast<std::uint8_t>(rng());
      if (i % 2 == 0 && noise.size() >= 2) noise[0] = good[0], noise[1] = good[1];
      const auto out = decoder.decode(noise, 0);
      if (out.status == PacketStatus::ok) {
        EXPECT_LE(out.points.size(), decoder.max_points_per_packet());
      }
    }
  }
}

// --- RoboSense ---------------------------------------------------------------

RoboSenseAngles robosense_angles() {
  RoboSenseAngles a;
  for (int i = 0; i < 16; ++i) {
    a.elevation_deg.push_back(-15.0F + 2.0F * static_cast<float>(i));
    a.azimuth_deg.push_back(0.0F);
  }
  return a;
}

TEST(RoboSenseAngleCsv, ParsesTabsAndRejectsBadRows) {
  std::string text;
  for (int i = 0; i < 16; ++i) text += std::to_string(i - 8) + ".5,-4.05\t\n";  // -8.5 .. 7.5
  const auto a = parse_robosense_angle_csv(text, "rs.csv");
  EXPECT_FLOAT_EQ(a.elevation_deg[0], -8.5F);
  EXPECT_FLOAT_EQ(a.azimuth_deg[15], -4.05F);
  EXPECT_THROW(parse_robosense_angle_csv("1,2\n", "rs.csv"), InputError);  // 1 row, not 16
  try {
    parse_robosense_angle_csv("1,2\nx,2\n", "rs.csv");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "rs.csv:2");
    EXPECT_EQ(e.key(), "elevation");
  }
  EXPECT_EQ(robosense_model_from_name("RS-16"), RoboSenseModel::rs16);
  EXPECT_EQ(robosense_model_from_name("helios-16p"), RoboSenseModel::helios16p);
}

TEST(RoboSenseDecoder, DecodesRs16AndHeliosHeadersTimesAndPositions) {
  for (const bool helios : {false, true}) {
    SCOPED_TRACE(helios ? "Helios16P" : "RS-16");
    RoboSenseDecoder decoder(helios ? RoboSenseModel::helios16p : RoboSenseModel::rs16, robosense_angles(),
                             RoboSenseReturnMode::single);
    const auto out = decoder.decode(test::robosense_msop(helios, 9000, 40), 0);
    ASSERT_EQ(out.status, PacketStatus::ok);
    ASSERT_EQ(out.points.size(), 12u * 32);
    EXPECT_EQ(out.sensor_time_ns, kPacketSecond * 1'000'000'000LL + 123'456'000LL);
    const double unit = helios ? 0.0025 : 0.005;
    const double rx = helios ? 0.03498 : 0.03825;
    // Block 0, channel 0: fires at the packet time, azimuth 90.00 deg, elevation -15 deg.
    const DecodedPoint& p = out.points[0];
    const double r = 2000 * unit;
    EXPECT_NEAR(p.point.x, r * std::cos(-15 * kDeg) * std::cos(90 * kDeg) + rx * std::cos(90 * kDeg), 1e-4);
    EXPECT_NEAR(p.point.y, -(r * std::cos(-15 * kDeg) * std::sin(90 * kDeg) + rx * std::sin(90 * kDeg)), 1e-4);
    EXPECT_NEAR(p.point.z, r * std::sin(-15 * kDeg), 1e-4);
    EXPECT_EQ(p.point.ring, 0);
    EXPECT_EQ(p.sensor_time_ns, out.sensor_time_ns);
    // Channel 16 is the second firing sequence of block 0, one sequence later.
    EXPECT_NEAR(static_cast<double>(out.points[16].sensor_time_ns - out.sensor_time_ns), helios ? 55'560 : 55'500, 1);
    // Block 1 starts two sequences after block 0.
    EXPECT_NEAR(static_cast<double>(out.points[32].sensor_time_ns - out.sensor_time_ns), helios ? 111'120 : 111'000, 1);
  }
}

TEST(RoboSenseDecoder, DualModeSharesFiringTimesBetweenReturns) {
  RoboSenseDecoder decoder(RoboSenseModel::helios16p, robosense_angles(), RoboSenseReturnMode::dual);
  const auto out = decoder.decode(test::robosense_msop(true, 100, 20), 0);
  ASSERT_EQ(out.status, PacketStatus::ok);
  EXPECT_EQ(out.points[3].sensor_time_ns, out.points[19].sensor_time_ns);
  EXPECT_EQ(out.points[3].point.return_index, 0);
  EXPECT_EQ(out.points[19].point.return_index, 1);
  EXPECT_EQ(out.points[32].sensor_time_ns - out.points[0].sensor_time_ns, 55'560);
}

TEST(RoboSenseDecoder, DifopSetsAnglesAndReturnMode) {
  RoboSenseDecoder decoder(RoboSenseModel::rs16, robosense_angles(), RoboSenseReturnMode::single);
  std::vector<std::uint8_t> difop(1248, 0);
  const std::uint8_t magic[] = {0xA5, 0xFF, 0x00, 0x5A, 0x11, 0x11, 0x55, 0x55};
  std::copy(std::begin(magic), std::end(magic), difop.begin());
  difop[8] = 0x02, difop[9] = 0x58;  // 600 rpm
  difop[300] = 0x00;                  // dual
  for (int i = 0; i < 16; ++i) {      // laser i at +i degrees, written as sign + 0.01 degree steps
    difop[468 + 3 * i] = 0;
    difop[469 + 3 * i] = static_cast<std::uint8_t>((i * 100) >> 8);
    difop[470 + 3 * i] = static_cast<std::uint8_t>(i * 100);
  }
  difop[468 + 3 * 15] = 1;  // laser 15 at -15 degrees: the lowest ring
  EXPECT_EQ(decoder.decode(difop, 0).status, PacketStatus::auxiliary);
  EXPECT_EQ(decoder.return_mode(), RoboSenseReturnMode::dual);
  EXPECT_EQ(decoder.counters().difop_calibrations_applied, 1u);
  const auto out = decoder.decode(test::robosense_msop(false, 0, 20), 0);
  ASSERT_EQ(out.status, PacketStatus::ok);
  EXPECT_EQ(out.points[15].point.ring, 0);
  EXPECT_NEAR(out.points[1].point.z, 2000 * 0.005 * std::sin(1 * kDeg), 1e-4);
  // A DIFOP with unwritten (0xFF) calibration keeps the angles.
  std::fill(difop.begin() + 468, difop.begin() + 468 + 96, 0xFF);
  EXPECT_EQ(decoder.decode(difop, 0).status, PacketStatus::auxiliary);
  EXPECT_EQ(decoder.counters().difop_calibrations_applied, 1u);
  EXPECT_EQ(decoder.decode(std::span(difop.data(), 100), 0).status, PacketStatus::truncated);
}

TEST(RoboSenseDecoder, BadPacketsComeBackWithAStatusNeverACrash) {
  for (const bool helios : {false, true}) {
    RoboSenseDecoder decoder(helios ? RoboSenseModel::helios16p : RoboSenseModel::rs16, robosense_angles(),
                             RoboSenseReturnMode::single);
    const auto good = test::robosense_msop(helios, 0, 20);
    for (std::size_t n = 0; n < good.size(); n += 7) EXPECT_NE(decoder.decode(std::span(good.data(), n), 0).status, PacketStatus::ok);
    EXPECT_EQ(decoder.decode(std::span(good.data(), 1247), 0).status, PacketStatus::truncated);
    auto oversized = good;
    oversized.push_back(0);
    EXPECT_EQ(decoder.decode(oversized, 0).status, PacketStatus::malformed);
    EXPECT_EQ(decoder.decode(test::robosense_msop(!helios, 0, 20), 0).status, PacketStatus::foreign);
    auto bad_block = good;
    bad_block[42 + 500] = 0x00;  // block 5's 0xFFEE flag
    EXPECT_EQ(decoder.decode(bad_block, 0).status, PacketStatus::malformed);
    auto bad_azimuth = good;
    bad_azimuth[44] = 0xFF, bad_azimuth[45] = 0xFF;
    EXPECT_EQ(decoder.decode(bad_azimuth, 0).status, PacketStatus::malformed);
    std::mt19937 rng(11);
    for (int i = 0; i < 300; ++i) {
      std::vector<std::uint8_t> noise(i % 3 == 0 ? 1248 : rng() % 1400);
      for (auto& byte : noise) byte = static_cast<std::uint8_t>(rng());
      if (i % 2 == 0) std::copy(good.begin(), good.begin() + std::min<std::size_t>(8, noise.size()), noise.begin());
      (void)decoder.decode(noise, 0);
    }
  }
}

TEST(LidarRegistry, DetectsEveryHesaiAndRoboSenseModel) {
  for (const auto& layout : test::hesai_layouts()) {
    const DetectedLidar found = detect_lidar(test::hesai_packet(layout), 2368);
    ASSERT_NE(found.family, nullptr) << layout.model;
    EXPECT_EQ(found.family->name, "hesai");
    EXPECT_EQ(found.model, layout.model);
  }
  for (const bool helios : {false, true}) {
    const DetectedLidar found = detect_lidar(test::robosense_msop(helios, 0, 20), 6699);
    ASSERT_NE(found.family, nullptr);
    EXPECT_EQ(found.family->name, "robosense");
    EXPECT_EQ(found.model, helios ? "Helios16P" : "RS-16");
  }
  const auto* hesai = find_lidar_family("hesai");
  ASSERT_NE(hesai, nullptr);
  test::HesaiContent dual;
  dual.return_mode = 0x39;
  EXPECT_EQ(hesai->packet_period_ns("PandarXT32", test::hesai_packet(test::hesai_layouts()[1], dual)), 200'000);
  EXPECT_EQ(hesai->packet_period_ns("PandarXT32", test::hesai_packet(test::hesai_layouts()[1])), 400'000);
  EXPECT_THROW(hesai->make_decoder("PandarXT32", ""), InputError);
  EXPECT_THROW(find_lidar_family("robosense")->make_decoder("RS-16", ""), InputError);
  std::vector<std::uint8_t> velodyne(1206, 0);
  velodyne[0] = 0xFF, velodyne[1] = 0xEE;
  const DetectedLidar other = detect_lidar(velodyne, 2368);
  if (other.family != nullptr) {
    EXPECT_EQ(other.family->name, "velodyne");
  }
}

}  // namespace
}  // namespace adit::drivers
