// VLS-128 dual return on synthetic packets (no real capture exists), built
// from the VLS-128 User Manual (63-9480) §9: a firing sequence may not span two
// packets, so a dual packet holds one 53.3 µs sequence in blocks 0-7, banks
// FFEE, FFDD, FFCC, FFBB (lasers 0-31, 32-63, 64-95, 96-127) each as a pair
// (last, strongest), and blocks 8-11 are padding. 8 lasers fire together every
// 2.665 µs, with an idle slot after the first 8 firing groups.
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
constexpr double kUnitM = 0.004;  // VLS-128 distance unit

// A permutation of the lasers, so that rings differ from laser ids.
int expected_ring(int laser) { return laser * 37 % kLasers; }
double elevation_rad(int laser) { return (expected_ring(laser) - 64) * 0.2 * std::numbers::pi / 180.0; }

VelodyneCalibration vls128_calibration() {
  VelodyneCalibration c;
  c.source = "synthetic";
  for (int l = 0; l < kLasers; ++l) {
    VelodyneLaser laser;
    laser.laser_id = l;
    laser.vert_correction = elevation_rad(l);
    c.lasers.push_back(laser);
  }
  return c;
}

// When laser l fires after the packet's timestamp (manual §9.5: FiringGroupIndex = l / 8 + l / 64,
// ExactPointTime = Timestamp + 2.665 µs x FiringGroupIndex - 8.7 µs).
std::int64_t firing_ns(int laser) {
  const int group = laser / 8 + laser / 64;
  return group * 2'665 - 8'700;
}

struct Echo {
  std::uint16_t raw = 0;
  std::uint8_t reflectivity = 0;
};
struct Echoes {
  std::array<Echo, kLasers> last{}, strongest{};
};

std::vector<std::uint8_t> vls128_dual_packet(int azimuth, std::uint32_t us_past_hour, const Echoes& e,
                                             std::uint8_t padding = 0) {
  std::vector<std::uint8_t> p(kVelodyneDataPacketSize, padding);
  for (int b = 0; b < 8; ++b) {
    std::uint8_t* block = p.data() + b * 100;
    const int bank = b / 2;
    block[0] = 0xFF;
    block[1] = static_cast<std::uint8_t>(0xEE - 0x11 * bank);
    block[2] = static_cast<std::uint8_t>(azimuth);
    block[3] = static_cast<std::uint8_t>(azimuth >> 8);
    const auto& echoes = b % 2 == 0 ? e.last : e.strongest;
    for (int c = 0; c < 32; ++c) {
      const Echo& echo = echoes[bank * 32 + c];
      block[4 + 3 * c] = static_cast<std::uint8_t>(echo.raw);
      block[4 + 3 * c + 1] = static_cast<std::uint8_t>(echo.raw >> 8);
      block[4 + 3 * c + 2] = echo.reflectivity;
    }
  }
  for (int i = 0; i < 4; ++i) p[1200 + i] = static_cast<std::uint8_t>(us_past_hour >> (8 * i));
  p[1204] = 0x39;
  p[1205] = 0xA1;
  return p;
}

Echoes distinct_echoes() {
  Echoes e;
  for (int l = 0; l < kLasers; ++l) {
    e.last[l] = {static_cast<std::uint16_t>(3000 + l), 10};
    e.strongest[l] = {static_cast<std::uint16_t>(1000 + l), 200};
  }
  return e;
}

TEST(VelodyneVls128Dual, DecodesBothReturnsOfEveryBankWithRingAndFiringTime) {
  VelodyneDecoder decoder(VelodyneModel::vls128, vls128_calibration());
  const std::int64_t host = 3'600'000'000'000 * 7 + 2'000'000'000;  // 7 h + 2 s
  const DecodedPacket d = decoder.decode(vls128_dual_packet(9000, 2'000'000, distinct_echoes()), host);
  ASSERT_EQ(d.status, PacketStatus::ok);
  EXPECT_EQ(decoder.last_return_mode(), VelodyneReturnMode::dual);
  ASSERT_EQ(d.points.size(), 2u * kLasers);
  EXPECT_EQ(d.sensor_time_ns, host - 8'700);  // the first firing, 8.7 µs before the stamp
  for (std::size_t i = 0; i < d.points.size(); ++i) {
    const int block = static_cast<int>(i) / 32;
    const int laser = block / 2 * 32 + static_cast<int>(i) % 32;
    const bool last = block % 2 == 0;
    const DecodedPoint& p = d.points[i];
    SCOPED_TRACE(testing::Message() << "point " << i << " laser " << laser);
    EXPECT_EQ(p.point.return_index, last ? 1 : 0);
    EXPECT_EQ(p.point.ring, expected_ring(laser));
    const double range = (last ? 3000 + laser : 1000 + laser) * kUnitM;
    EXPECT_NEAR(p.point.range_m, range, 1e-4);
    EXPECT_FLOAT_EQ(p.point.intensity, last ? 10.0F : 200.0F);
    EXPECT_NEAR(p.point.z, range * std::sin(elevation_rad(laser)), 1e-4);
    // Both returns of a laser come from the same firing.
    EXPECT_EQ(p.sensor_time_ns, host + firing_ns(laser));
    // The first packet gives no rotation rate yet: the block azimuth, 90° (clockwise: to the right).
    EXPECT_FLOAT_EQ(p.azimuth_deg, 90.0F);
    EXPECT_NEAR(p.point.x, 0.0, 1e-4);
    EXPECT_NEAR(p.point.y, -range * std::cos(elevation_rad(laser)), 1e-4);
  }
  // Laser 127: firing group 15, after the idle slot.
  EXPECT_EQ(d.points.back().sensor_time_ns - d.points.front().sensor_time_ns, 16 * 2'665);
}

TEST(VelodyneVls128Dual, InterpolatesAzimuthWithTheAdvanceSincePreviousPacket) {
  VelodyneDecoder decoder(VelodyneModel::vls128, vls128_calibration());
  const Echoes e = distinct_echoes();
  ASSERT_EQ(decoder.decode(vls128_dual_packet(35990, 1'000, e), 0).status, PacketStatus::ok);
  // The next sequence 53 µs later (the timestamp counts whole µs), 0.20° further, across 0°.
  const DecodedPacket d = decoder.decode(vls128_dual_packet(10, 1'053, e), 0);
  ASSERT_EQ(d.status, PacketStatus::ok);
  const double advance = std::round(20.0 * 53'300 / 53'000);  // 0.01° per 53.3 µs sequence
  for (std::size_t i = 0; i < d.points.size(); ++i) {
    const int laser = static_cast<int>(i) / 64 * 32 + static_cast<int>(i) % 32;
    const double az = std::round(10 + advance * static_cast<double>(firing_ns(laser) + 8'700) / 53'300.0);
    EXPECT_NEAR(d.points[i].azimuth_deg, az / 100.0, 1e-4) << "laser " << laser;
  }
  // The last firing group: 0.8 of the way to the next sequence.
  EXPECT_NEAR(d.points.back().azimuth_deg, 0.26F, 1e-4F);
  // After a pause (a long loss) the step is not re-measured: the last one is kept.
  const DecodedPacket later = decoder.decode(vls128_dual_packet(18000, 900'000, e), 0);
  ASSERT_EQ(later.status, PacketStatus::ok);
  EXPECT_NEAR(later.points.back().azimuth_deg, 180.16F, 1e-4F);
}

TEST(VelodyneVls128Dual, IdenticalReturnsAreOnePointAndEmptyOnesNone) {
  VelodyneDecoder decoder(VelodyneModel::vls128, vls128_calibration());
  Echoes e = distinct_echoes();
  // Manual: when only one return is detected, both blocks of the pair hold the same data.
  for (const int l : {0, 5, 40, 127}) e.strongest[l] = e.last[l];
  e.last[70] = e.strongest[70] = {};  // no return at all
  const DecodedPacket d = decoder.decode(vls128_dual_packet(100, 5'000, e), 0);
  ASSERT_EQ(d.status, PacketStatus::ok);
  ASSERT_EQ(d.points.size(), 2u * kLasers - 4 - 2);
  int singles = 0;
  for (const DecodedPoint& p : d.points) {
    for (const int l : {0, 5, 40, 127}) {
      if (p.point.ring == expected_ring(l)) {
        ++singles;
        EXPECT_EQ(p.point.return_index, 0) << "laser " << l;  // one echo: reported as the strongest
        EXPECT_NEAR(p.point.range_m, (3000 + l) * kUnitM, 1e-4);
      }
    }
    EXPECT_NE(p.point.ring, expected_ring(70));
  }
  EXPECT_EQ(singles, 4);
}

TEST(VelodyneVls128Dual, IgnoresPaddingAndRejectsMisplacedBanks) {
  VelodyneDecoder decoder(VelodyneModel::vls128, vls128_calibration());
  const Echoes e = distinct_echoes();
  const DecodedPacket clean = decoder.decode(vls128_dual_packet(100, 5'000, e), 0);
  const std::vector<DecodedPoint> expected(clean.points.begin(), clean.points.end());
  const DecodedPacket padded = decoder.decode(vls128_dual_packet(100, 5'000, e, 0xFF), 0);
  ASSERT_EQ(padded.status, PacketStatus::ok);
  ASSERT_EQ(padded.points.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(padded.points[i].point.range_m, expected[i].point.range_m);
  }

  auto bank_order = vls128_dual_packet(100, 5'000, e);
  bank_order[1 * 100 + 1] = 0xDD;  // the single-return order FFEE, FFDD, ... instead of pairs
  EXPECT_EQ(decoder.decode(bank_order, 0).status, PacketStatus::malformed);
  auto bad_bank = vls128_dual_packet(100, 5'000, e);
  bad_bank[7 * 100 + 1] = 0xCC;
  EXPECT_EQ(decoder.decode(bad_bank, 0).status, PacketStatus::malformed);
  auto bad_azimuth = vls128_dual_packet(100, 5'000, e);
  bad_azimuth[6 * 100 + 3] = 0xFF;
  EXPECT_EQ(decoder.decode(bad_azimuth, 0).status, PacketStatus::malformed);
}

TEST(VelodyneVls128Dual, SendsOnePacketPerFiringSequence) {
  // Single return: 3 sequences per packet, 6254 packets/s; dual: 1 sequence, three times as many.
  EXPECT_NEAR(1e9 / velodyne_packet_period_ns(VelodyneModel::vls128, VelodyneReturnMode::dual), 18'762.0, 1);
  EXPECT_NEAR(1e9 / velodyne_packet_period_ns(VelodyneModel::vls128, VelodyneReturnMode::last), 6'254.0, 1);
}

}  // namespace
}  // namespace adit::drivers
