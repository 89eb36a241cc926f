// The live path allocates nothing per packet: decode() of lidar and IMU
// packets, good or bad, and ScanAssembler::add() in steady state.
// (Its own executable: it replaces the global operator new to count.)
#include <gtest/gtest.h>

#include <string>

#include "adit/drivers/lidar/ouster_decoder.hpp"
#include "adit/drivers/lidar/ouster_encoder.hpp"
#include "adit/drivers/lidar/scan_assembler.hpp"
#include "allocation_counter.hpp"

namespace adit::drivers {
namespace {

TEST(OusterDecoder, DecodingAndAssemblingAllocateNothingPerPacket) {
  ADIT_REQUIRE_ALLOCATION_COUNTING();
  OusterMetadata m;
  m.lidar_mode = "1024x10";
  m.columns_per_frame = 1024;
  m.columns_per_packet = 16;
  m.pixels_per_column = 64;
  for (int i = 0; i < 64; ++i) {
    m.beam_altitude_deg.push_back(20.0 - i * 0.6);
    m.beam_azimuth_deg.push_back(i % 4 - 1.5);
    m.pixel_shift_by_row.push_back(0);
  }
  m.beam_to_lidar = {1, 0, 0, 15.8, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  m.lidar_to_sensor = {-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 36.18, 0, 0, 0, 1};
  m.column_window = {0, 1023};
  m.lidar_profile = OusterProfile::rng19_rfl8_sig16_nir16;
  OusterDecoder decoder(m);
  ScanAssembler assembler({.max_points_per_scan = 1024 * 64, .sequence_modulus = decoder.sequence_modulus()});

  // Two frames of packets, built beforehand.
  std::vector<std::vector<std::uint8_t>> packets;
  for (std::uint16_t frame = 0; frame < 2; ++frame)
    for (int p = 0; p < 64; ++p) {
      std::vector<std::uint8_t> packet(decoder.layout().packet_bytes);
      OusterPacketEncoder b(decoder.layout(), packet);
      b.frame_id(frame);
      for (int c = 0; c < 16; ++c) {
        const auto mid = static_cast<std::uint16_t>(p * 16 + c);
        b.column_header(c, 1'000'000'000ULL * frame + 97'656ULL * mid, mid);
        for (int row = 0; row < 64; ++row) b.pixel(c, row, 1000 + row, 10, 20, 30);
      }
      packets.push_back(packet);
    }
  const std::vector<std::uint8_t> imu(48, 0);
  const std::vector<std::uint8_t> junk(100, 0xAB);

  // Warm up one frame (the assembler's scans reach their reserved size).
  for (int p = 0; p < 64; ++p) (void)assembler.add(decoder.decode(packets[static_cast<std::size_t>(p)], 0));
  const std::uint64_t before = adit::test::allocations();
  int scans = 0;
  for (std::size_t p = 64; p < packets.size(); ++p) {
    scans += assembler.add(decoder.decode(packets[p], 0)) != nullptr;
    (void)decoder.decode(imu, 0);
    (void)decoder.decode(junk, 0);
  }
  EXPECT_EQ(adit::test::allocations() - before, 0U);
  EXPECT_EQ(scans, 1);
  // The counter does count: a heap string bumps it.
  const std::uint64_t probe_before = adit::test::allocations();
  const std::string probe(200, 'x');
  EXPECT_EQ(probe.size(), 200U);
  EXPECT_GT(adit::test::allocations(), probe_before);
}

}  // namespace
}  // namespace adit::drivers
