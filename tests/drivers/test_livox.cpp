// Livox Mid-360 (SDK2) and Avia (SDK1): packets written here field by field
// from the protocol documents (Livox-SDK2 livox_lidar_def.h and livox_ros_driver2
// pub_handler.cpp; Livox-SDK livox_def.h and livox_ros_driver lds.h), independently
// of the encoder; then our encoder -> our decoder round trips, scans cut by time
// window, IMU packets and bad input. No real Livox capture is public (none found).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/livox.hpp"
#include "adit/drivers/lidar/livox_encoder.hpp"
#include "adit/drivers/lidar/registry.hpp"

namespace adit::drivers {
namespace {

struct Bytes {
  std::vector<std::uint8_t> v;
  void u8(unsigned x) { v.push_back(static_cast<std::uint8_t>(x)); }
  void u16(unsigned x) { u8(x & 0xFF), u8((x >> 8) & 0xFF); }
  void u32(std::uint32_t x) { u16(x & 0xFFFF), u16(x >> 16); }
  void u64(std::uint64_t x) { u32(static_cast<std::uint32_t>(x)), u32(static_cast<std::uint32_t>(x >> 32)); }
  void i32(std::int32_t x) { u32(static_cast<std::uint32_t>(x)); }
  void f32(float x) { u32(std::bit_cast<std::uint32_t>(x)); }
  void zeros(int n) { v.insert(v.end(), static_cast<std::size_t>(n), 0); }
};

constexpr std::int64_t kT0 = 1'700'000'000'123'456'789;  // ns, gPTP time

// Point i of the test pattern, mm.
std::int32_t px(int i) { return 1000 + 37 * i; }
std::int32_t py(int i) { return -500 + 11 * i; }
std::int32_t pz(int i) { return 200 - 3 * i; }

// SDK2 cartesian-high packet of n points, field by field (livox_lidar_def.h).
std::vector<std::uint8_t> sdk2_points(int n, std::int64_t t0, std::uint16_t time_interval, std::uint16_t udp_cnt) {
  Bytes b;
  b.u8(0);                      // version
  b.u16(36 + 14 * n);           // length
  b.u16(time_interval);         // 0.1 µs
  b.u16(n);                     // dot_num
  b.u16(udp_cnt);
  b.u8(7);                      // frame_cnt
  b.u8(1);                      // data_type: cartesian high
  b.u8(1);                      // time_type: gPTP
  b.zeros(12);                  // reserved
  b.u32(0);                     // crc32 (not checked)
  b.u64(static_cast<std::uint64_t>(t0));
  for (int i = 0; i < n; ++i) {
    b.i32(px(i)), b.i32(py(i)), b.i32(pz(i)), b.u8(i), b.u8(0x10);
  }
  return b.v;
}

TEST(LivoxSdk2, PointPacketDecodesFieldByField) {
  const auto p = sdk2_points(96, kT0, 4800, 321);  // 480 µs: 5 µs per point
  ASSERT_EQ(p.size(), 1380u);
  EXPECT_EQ(livox_model_from_packet(p), LivoxModel::mid360);
  LivoxDecoder decoder(LivoxModel::mid360);
  const DecodedPacket d = decoder.decode(p, 0);
  ASSERT_EQ(d.status, PacketStatus::ok);
  ASSERT_EQ(d.points.size(), 96u);
  ASSERT_TRUE(d.sequence);
  EXPECT_EQ(*d.sequence, 321u);
  EXPECT_EQ(d.sensor_time_ns, kT0);
  for (int i = 0; i < 96; ++i) {
    const DecodedPoint& pt = d.points[static_cast<std::size_t>(i)];
    SCOPED_TRACE(i);
    EXPECT_FLOAT_EQ(pt.point.x, px(i) * 0.001F);
    EXPECT_FLOAT_EQ(pt.point.y, py(i) * 0.001F);
    EXPECT_FLOAT_EQ(pt.point.z, pz(i) * 0.001F);
    EXPECT_NEAR(pt.point.range_m, std::sqrt(1e-6 * (px(i) * px(i) + py(i) * py(i) + pz(i) * pz(i))), 1e-5);
    EXPECT_EQ(pt.point.intensity, static_cast<float>(i));
    EXPECT_EQ(pt.point.ring, i % 4);  // Mid-360: 4 lines, as livox_ros_driver2 numbers them
    // pub_handler.cpp: point_interval = time_interval * 100 / dot_num ns.
    EXPECT_EQ(pt.sensor_time_ns, kT0 + i * (4800 * 100 / 96));
    // The time-window phase that cuts scans: 360° per 100 ms.
    EXPECT_NEAR(pt.azimuth_deg, static_cast<double>(pt.sensor_time_ns % 100'000'000) * 360.0 / 1e8, 1e-3);
  }
  EXPECT_EQ(livox_packet_period_ns(LivoxModel::mid360, p), 480'000);
}

TEST(LivoxSdk2, LowAndSphericalFormats) {
  LivoxDecoder decoder(LivoxModel::mid360);
  Bytes low;
  low.u8(0), low.u16(36 + 8), low.u16(50), low.u16(1), low.u16(1), low.u8(0), low.u8(2), low.u8(0), low.zeros(16);
  low.u64(1000);
  low.u16(static_cast<std::uint16_t>(std::int16_t{-250})), low.u16(100), low.u16(30), low.u8(9), low.u8(0);  // cm
  DecodedPacket d = decoder.decode(low.v, 0);
  ASSERT_EQ(d.status, PacketStatus::ok);
  ASSERT_EQ(d.points.size(), 1u);
  EXPECT_FLOAT_EQ(d.points[0].point.x, -2.5F);
  EXPECT_FLOAT_EQ(d.points[0].point.y, 1.0F);
  EXPECT_FLOAT_EQ(d.points[0].point.z, 0.3F);

  Bytes sph;
  sph.u8(0), sph.u16(36 + 10), sph.u16(50), sph.u16(1), sph.u16(2), sph.u8(0), sph.u8(3), sph.u8(0), sph.zeros(16);
  sph.u64(1000);
  sph.u32(10'000), sph.u16(6000), sph.u16(9000), sph.u8(5), sph.u8(0);  // 10 m, zenith 60°, azimuth 90°
  d = decoder.decode(sph.v, 0);
  ASSERT_EQ(d.status, PacketStatus::ok);
  ASSERT_EQ(d.points.size(), 1u);
  EXPECT_NEAR(d.points[0].point.x, 0.0, 1e-4);
  EXPECT_NEAR(d.points[0].point.y, 10.0 * std::sin(60.0 * M_PI / 180.0), 1e-4);
  EXPECT_NEAR(d.points[0].point.z, 5.0, 1e-4);
}

TEST(LivoxSdk2, EncoderRoundTripIsExact) {
  std::vector<LivoxRawPoint> pts(96);
  std::mt19937 rng(3);
  for (auto& p : pts) {
    p.x_mm = static_cast<std::int32_t>(rng() % 80'000) - 40'000;
    p.y_mm = static_cast<std::int32_t>(rng() % 80'000) - 40'000;
    p.z_mm = static_cast<std::int32_t>(rng() % 20'000) - 10'000;
    p.reflectivity = static_cast<std::uint8_t>(rng());
  }
  pts[5] = {};  // no return
  LivoxSdk2PointPacket in;
  in.time_ns = kT0;
  in.time_interval = 4800;
  in.udp_cnt = 65535;
  in.points = pts;
  std::vector<std::uint8_t> bytes(livox_sdk2_point_packet_bytes(pts.size()));
  encode_livox_sdk2_points(in, bytes);
  // The field-by-field packet and the encoder's agree byte for byte outside the payload and CRC.
  EXPECT_EQ(bytes[0], 0);
  EXPECT_EQ(bytes[1] | bytes[2] << 8, 1380);
  EXPECT_EQ(livox_crc32({bytes.data() + 36, bytes.size() - 36}), bytes[24] | bytes[25] << 8 | bytes[26] << 16 | static_cast<std::uint32_t>(bytes[27]) << 24);
  LivoxDecoder decoder(LivoxModel::mid360);
  const DecodedPacket d = decoder.decode(bytes, 0);
  ASSERT_EQ(d.status, PacketStatus::ok);
  ASSERT_EQ(d.points.size(), 95u);
  EXPECT_EQ(*d.sequence, 65535u);
  std::size_t j = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (i == 5) continue;
    const DecodedPoint& p = d.points[j++];
    EXPECT_EQ(std::lround(p.point.x * 1000.0F), pts[i].x_mm);
    EXPECT_EQ(std::lround(p.point.y * 1000.0F), pts[i].y_mm);
    EXPECT_EQ(std::lround(p.point.z * 1000.0F), pts[i].z_mm);
    EXPECT_EQ(p.point.intensity, pts[i].reflectivity);
    EXPECT_EQ(p.sensor_time_ns, kT0 + static_cast<std::int64_t>(i) * 5000);
  }
}

TEST(LivoxSdk2, ImuPacketIsAuxiliaryWithItsReading) {
  // 36-byte header (data type 0, dot_num 1) + gyro x y z (rad/s), acc x y z (g).
  Bytes b;
  b.u8(0), b.u16(60), b.u16(0), b.u16(1), b.u16(9), b.u8(0), b.u8(0), b.u8(1), b.zeros(16);
  b.u64(static_cast<std::uint64_t>(kT0));
  b.f32(0.1F), b.f32(-0.2F), b.f32(0.3F), b.f32(0.0F), b.f32(0.5F), b.f32(-1.0F);
  const auto reading = decode_livox_imu(b.v);
  ASSERT_TRUE(reading);
  EXPECT_EQ(reading->sensor_time_ns, kT0);
  EXPECT_FLOAT_EQ(reading->gyro_rad_s[1], -0.2F);
  EXPECT_NEAR(reading->accel_m_s2[2], -9.80665, 1e-5);
  EXPECT_NEAR(reading->accel_m_s2[1], 0.5 * 9.80665, 1e-5);
  LivoxDecoder decoder(LivoxModel::mid360);
  EXPECT_EQ(decoder.decode(b.v, 0).status, PacketStatus::auxiliary);
  ASSERT_TRUE(decoder.last_imu());
  EXPECT_FLOAT_EQ(decoder.last_imu()->gyro_rad_s[0], 0.1F);
  // The encoder writes the same bytes.
  std::vector<std::uint8_t> enc(kLivoxSdk2ImuPacketBytes);
  const float gyro[3] = {0.1F, -0.2F, 0.3F};
  const float acc[3] = {0.0F, 0.5F, -1.0F};
  encode_livox_sdk2_imu(kT0, 9, gyro, acc, enc);
  for (std::size_t i = 0; i < enc.size(); ++i) {
    if (i >= 24 && i < 28) continue;  // CRC: the field-by-field packet leaves it 0
    EXPECT_EQ(enc[i], b.v[i]) << "byte " << i;
  }
}

// SDK1 extend cartesian (type 2) and dual (type 4), field by field (livox_def.h).
std::vector<std::uint8_t> sdk1_points(std::uint8_t type, std::uint8_t time_type, const Bytes& stamp) {
  Bytes b;
  b.u8(5), b.u8(1), b.u8(0), b.u8(0), b.u32(0), b.u8(time_type), b.u8(type);
  b.v.insert(b.v.end(), stamp.v.begin(), stamp.v.end());
  const int records = type == 2 ? 96 : 48;
  for (int r = 0; r < records; ++r) {
    for (int k = 0; k < (type == 2 ? 1 : 2); ++k) {
      const int i = r * 2 + k;
      b.i32(px(i)), b.i32(py(i)), b.i32(pz(i)), b.u8(k == 0 ? 40 : 20), b.u8(0);
    }
  }
  return b.v;
}

TEST(LivoxSdk1, AviaSingleAndDualPacketsDecodeFieldByField) {
  Bytes stamp;
  stamp.u64(static_cast<std::uint64_t>(kT0));
  const auto single = sdk1_points(2, 1, stamp);
  ASSERT_EQ(single.size(), 1362u);
  EXPECT_EQ(livox_model_from_packet(single), LivoxModel::avia);
  LivoxDecoder decoder(LivoxModel::avia);
  DecodedPacket d = decoder.decode(single, 0);
  ASSERT_EQ(d.status, PacketStatus::ok);
  ASSERT_EQ(d.points.size(), 96u);
  EXPECT_FALSE(d.sequence);
  EXPECT_FLOAT_EQ(d.points[10].point.x, px(20) * 0.001F);  // the single packet uses the even pattern indices
  EXPECT_EQ(d.points[10].sensor_time_ns, kT0 + 10 * 4167);  // 240 k points/s (livox_ros_driver lds.h)
  EXPECT_EQ(d.points[10].point.ring, 10 % 6);
  EXPECT_EQ(livox_packet_period_ns(LivoxModel::avia, single), 96 * 4167);

  const auto dual = sdk1_points(4, 1, stamp);
  ASSERT_EQ(dual.size(), 1362u);
  d = decoder.decode(dual, 0);
  ASSERT_EQ(d.status, PacketStatus::ok);
  ASSERT_EQ(d.points.size(), 96u);
  for (int r = 0; r < 48; ++r) {
    const DecodedPoint& first = d.points[static_cast<std::size_t>(2 * r)];
    const DecodedPoint& second = d.points[static_cast<std::size_t>(2 * r + 1)];
    EXPECT_EQ(first.sensor_time_ns, kT0 + r * 4167);
    EXPECT_EQ(second.sensor_time_ns, first.sensor_time_ns);
    EXPECT_EQ(first.point.return_index, 0);
    EXPECT_EQ(second.point.return_index, 1);
    EXPECT_FLOAT_EQ(second.point.y, py(2 * r + 1) * 0.001F);
  }
  EXPECT_EQ(livox_packet_period_ns(LivoxModel::avia, dual), 48 * 4167);
}

TEST(LivoxSdk1, GpsUtcTimestamp) {
  Bytes stamp;  // 2024-03-14 15:00 + 1234.5678 s
  stamp.u8(24), stamp.u8(3), stamp.u8(14), stamp.u8(15), stamp.u32(1'234'567'800);
  LivoxDecoder decoder(LivoxModel::avia);
  const DecodedPacket d = decoder.decode(sdk1_points(2, 3, stamp), 0);
  ASSERT_EQ(d.status, PacketStatus::ok);
  EXPECT_EQ(d.sensor_time_ns, (1710428400LL + 1234) * 1'000'000'000LL + 567'800'000);
}

TEST(LivoxSdk1, EncoderRoundTripAndImu) {
  std::array<LivoxRawPoint, 96> pts{};
  for (int i = 0; i < 96; ++i) pts[static_cast<std::size_t>(i)] = {px(i), py(i), pz(i), static_cast<std::uint8_t>(i), 0};
  std::vector<std::uint8_t> bytes(kLivoxSdk1PointPacketBytes);
  encode_livox_sdk1_points(kT0, true, pts, bytes);
  Bytes stamp;
  stamp.u64(static_cast<std::uint64_t>(kT0));
  auto expected = sdk1_points(4, 0, stamp);
  expected[1] = 0;  // slot: the encoder writes 0
  for (int i = 0; i < 96; ++i) expected[18 + 14 * static_cast<std::size_t>(i) + 12] = static_cast<std::uint8_t>(i);
  EXPECT_EQ(bytes, expected);
  const float gyro[3] = {1, 2, 3};
  const float acc[3] = {0, 0, 1};
  std::vector<std::uint8_t> imu(kLivoxSdk1ImuPacketBytes);
  encode_livox_sdk1_imu(kT0, gyro, acc, imu);
  LivoxDecoder decoder(LivoxModel::avia);
  EXPECT_EQ(decoder.decode(imu, 0).status, PacketStatus::auxiliary);
  ASSERT_TRUE(decoder.last_imu());
  EXPECT_NEAR(decoder.last_imu()->accel_m_s2[2], 9.80665, 1e-5);
  EXPECT_EQ(decoder.last_imu()->sensor_time_ns, kT0);
}

TEST(Livox, ScansAreCutByTimeWindowAndLossIsCountedByUdpCount) {
  LivoxDecoder decoder(LivoxModel::mid360);
  ScanAssembler assembler(assembler_config_for(decoder, 480'000, 0.0F));
  std::vector<std::pair<std::int64_t, std::size_t>> scans;  // start, points
  std::vector<bool> complete;
  DecodeStream stream(decoder, assembler, [&](LidarScan& s) {
    scans.emplace_back(s.sensor_start_time_ns, s.points.size());
    complete.push_back(s.stats.complete);
  });
  const std::int64_t start = 1'700'000'000'000'000'000 + 30'000'000;  // 30 ms into a window
  for (int k = 0; k < 700; ++k) {  // 336 ms
    if (k == 400) continue;       // one lost packet
    std::vector<LivoxRawPoint> pts(96, LivoxRawPoint{5000, 0, 0, 10, 0});
    LivoxSdk2PointPacket in;
    in.time_ns = start + k * 480'000LL;
    in.time_interval = 4800;
    in.udp_cnt = static_cast<std::uint16_t>(65000 + k);  // wraps
    in.points = pts;
    std::vector<std::uint8_t> bytes(livox_sdk2_point_packet_bytes(pts.size()));
    encode_livox_sdk2_points(in, bytes);
    stream.push(bytes, in.time_ns + 200'000);
  }
  stream.finish();
  ASSERT_EQ(scans.size(), 4u);  // 30-100, 100-200, 200-300, 300-366 ms
  for (std::size_t i = 1; i + 1 < scans.size(); ++i) {
    EXPECT_EQ(scans[i].first % 100'000'000, 0) << i;       // cut exactly at the window
    EXPECT_NEAR(static_cast<double>(scans[i].second), 20'000.0, 100.0) << i;  // 200 k points/s
  }
  EXPECT_FALSE(complete[0]);  // began mid-window
  EXPECT_TRUE(complete[1]);
  EXPECT_FALSE(complete[2]);  // lost a packet (k = 400: 222 ms)
  EXPECT_EQ(assembler.totals().missing_packets, 1u);
}

TEST(Livox, RegistryDetectsBothAndMakesDecoders) {
  const DetectedLidar mid = detect_lidar(sdk2_points(96, kT0, 4800, 1), kLivoxMid360PointPort);
  ASSERT_NE(mid.family, nullptr);
  EXPECT_EQ(mid.family->name, "livox");
  EXPECT_EQ(mid.model, "Mid-360");
  Bytes stamp;
  stamp.u64(1);
  const DetectedLidar avia = detect_lidar(sdk1_points(2, 0, stamp), 56001);
  ASSERT_NE(avia.family, nullptr);
  EXPECT_EQ(avia.model, "Avia");
  EXPECT_EQ(lidar_family_of_model("Mid-360"), mid.family);
  EXPECT_EQ(lidar_family_of_model("Avia"), mid.family);
  EXPECT_EQ(mid.family->make_decoder("MID360", {})->model(), "Mid-360");
  EXPECT_EQ(livox_model_from_name("livox avia"), LivoxModel::avia);
  EXPECT_FALSE(livox_model_from_name("Mid-70"));
}

TEST(Livox, BadPacketsComeBackWithAStatusNeverACrash) {
  for (const LivoxModel model : {LivoxModel::mid360, LivoxModel::avia}) {
    LivoxDecoder decoder(model);
    Bytes stamp;
    stamp.u64(static_cast<std::uint64_t>(kT0));
    const auto good = model == LivoxModel::mid360 ? sdk2_points(96, kT0, 4800, 1) : sdk1_points(2, 0, stamp);
    ASSERT_EQ(decoder.decode(good, 0).status, PacketStatus::ok);
    for (std::size_t n = 0; n < good.size(); ++n) {
      const DecodedPacket d = decoder.decode(std::span(good.data(), n), 0);
      EXPECT_NE(d.status, PacketStatus::ok) << n;
      EXPECT_TRUE(d.points.empty());
    }
    EXPECT_EQ(decoder.decode(std::span(good.data(), good.size() - 1), 0).status, PacketStatus::truncated);
    auto longer = good;
    longer.push_back(0);
    EXPECT_EQ(decoder.decode(longer, 0).status, PacketStatus::malformed);
    auto bad_type = good;
    bad_type[model == LivoxModel::mid360 ? 10 : 9] = 0x77;
    EXPECT_EQ(decoder.decode(bad_type, 0).status, PacketStatus::malformed);
    auto other_version = good;
    other_version[0] = 9;
    EXPECT_EQ(decoder.decode(other_version, 0).status, PacketStatus::foreign);
    std::vector<std::uint8_t> velodyne(1206, 0);
    velodyne[0] = 0xFF, velodyne[1] = 0xEE;
    EXPECT_EQ(decoder.decode(velodyne, 0).status, PacketStatus::foreign);
    std::mt19937 rng(11);
    for (int i = 0; i < 2000; ++i) {
      std::vector<std::uint8_t> noise(rng() % 1500);
      for (auto& byte : noise) byte = static_cast<std::uint8_t>(rng());
      if (!noise.empty() && i % 2 == 0) noise[0] = good[0];
      if (noise.size() > 2 && i % 4 == 0 && model == LivoxModel::mid360) {
        noise[1] = static_cast<std::uint8_t>(noise.size()), noise[2] = static_cast<std::uint8_t>(noise.size() >> 8);
      }
      const DecodedPacket d = decoder.decode(noise, 0);
      EXPECT_LE(d.points.size(), decoder.max_points_per_packet());
    }
  }
  // A Mid-360 packet claiming more points than a datagram can hold.
  LivoxDecoder decoder(LivoxModel::mid360);
  const auto big = sdk2_points(200, kT0, 4800, 1);
  EXPECT_EQ(decoder.decode(big, 0).status, PacketStatus::malformed);
}

}  // namespace
}  // namespace adit::drivers
