// The Ouster decoder on real captures: geometry against the firmware manual's
// equations evaluated directly in double, scan assembly, IMU packets.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/ouster_decoder.hpp"
#include "adit/drivers/lidar/scan_assembler.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "shared_data.hpp"

namespace adit::drivers {
namespace {

namespace fs = std::filesystem;

// Manual, "Lidar Range to XYZ", for pixel (row, column) at range r mm, in metres.
std::array<double, 3> manual_xyz(const OusterMetadata& m, int row, int col, double r) {
  const double two_pi = 2 * std::numbers::pi;
  const double te = two_pi * (1.0 - static_cast<double>(col) / m.columns_per_frame);
  const double ta = -two_pi * m.beam_azimuth_deg[static_cast<std::size_t>(row)] / 360.0;
  const double phi = two_pi * m.beam_altitude_deg[static_cast<std::size_t>(row)] / 360.0;
  const double bx = m.beam_to_lidar[3];
  const double bz = m.beam_to_lidar[11];
  const double n = std::sqrt(bx * bx + bz * bz);
  const double l[3] = {(r - n) * std::cos(te + ta) * std::cos(phi) + bx * std::cos(te),
                       (r - n) * std::sin(te + ta) * std::cos(phi) + bx * std::sin(te), (r - n) * std::sin(phi) + bz};
  std::array<double, 3> s{};
  const auto& t = m.lidar_to_sensor;
  for (int i = 0; i < 3; ++i) s[i] = (t[4 * i] * l[0] + t[4 * i + 1] * l[1] + t[4 * i + 2] * l[2] + t[4 * i + 3]) / 1000;
  return s;
}

struct Decoded {
  std::vector<LidarScan> scans;
  ScanAssemblerTotals totals;
  std::uint64_t imu_packets = 0;
  double max_xyz_error_m = 0;
  std::uint64_t points = 0;
  std::vector<OusterImuSample> imu;
};

Decoded decode_capture(const fs::path& pcap, const OusterMetadata& m) {
  OusterDecoder decoder(m);
  ScanAssembler assembler({.cut_azimuth_deg = 0.0F,
                           .max_points_per_scan = static_cast<std::size_t>(m.columns_per_frame) *
                                                  static_cast<std::size_t>(m.pixels_per_column) * 2,
                           .sequence_modulus = decoder.sequence_modulus()});
  // Row of each ring, to find a point's pixel again.
  std::vector<int> row_of_ring(m.beam_altitude_deg.size());
  for (std::size_t row = 0; row < m.beam_altitude_deg.size(); ++row) {
    std::size_t below = 0;
    for (std::size_t k = 0; k < m.beam_altitude_deg.size(); ++k)
      below += m.beam_altitude_deg[k] < m.beam_altitude_deg[row] || (m.beam_altitude_deg[k] == m.beam_altitude_deg[row] && k < row);
    row_of_ring[below] = static_cast<int>(row);
  }
  Decoded out;
  PcapReader reader(pcap);
  UdpDatagram d;
  while (reader.next(d)) {
    const DecodedPacket p = decoder.decode(d.payload, 0);
    if (p.status == PacketStatus::auxiliary) out.imu.push_back(decoder.last_imu());
    for (const DecodedPoint& dp : p.points) {
      const int col = static_cast<int>(std::lround(dp.azimuth_deg * m.columns_per_frame / 360.0));
      const auto e = manual_xyz(m, row_of_ring[dp.point.ring], col, std::round(dp.point.range_m * 1000.0));
      out.max_xyz_error_m = std::max({out.max_xyz_error_m, std::abs(e[0] - dp.point.x), std::abs(e[1] - dp.point.y),
                                      std::abs(e[2] - dp.point.z)});
      ++out.points;
    }
    if (LidarScan* s = assembler.add(p)) out.scans.push_back(*s);
  }
  if (LidarScan* s = assembler.flush()) out.scans.push_back(*s);
  out.totals = assembler.totals();
  out.imu_packets = decoder.counters().imu_packets;
  return out;
}

TEST(OusterRealData, ThreeFramesOfOs1_128AssembleIntoScans) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster");
  const auto m = load_ouster_metadata(dir / "OS-1-128_v2.3.0_1024x10.json");
  const Decoded d = decode_capture(dir / "OS-1-128_v2.3.0_1024x10_lb_n3.pcap", m);
  EXPECT_LT(d.max_xyz_error_m, 1e-3);  // float LUT against double equations, up to ~100 m
  EXPECT_GT(d.points, 3U * 1024U * 128U / 2U);
  EXPECT_EQ(d.totals.packets, 192U);
  EXPECT_EQ(d.totals.missing_packets, 0U);
  EXPECT_EQ(d.totals.duplicate_packets, 0U);
  EXPECT_EQ(d.totals.out_of_order_packets, 0U);
  // 3 frames, each from column 0 to 1023: the first two are cut at the next
  // frame's column 0, the last is flushed at the end of the capture.
  ASSERT_EQ(d.scans.size(), 3U);
  EXPECT_EQ(d.scans[0].stats.packets, 64U);
  EXPECT_EQ(d.scans[1].stats.packets, 64U);
  EXPECT_TRUE(d.scans[1].stats.complete);
  for (const LidarScan& s : d.scans) {
    // 10 Hz: every firing within one revolution of the scan start.
    for (const LidarPoint& p : s.points) ASSERT_LT(p.time_offset_ns, 100'000'000U);
    EXPECT_GT(s.points.back().time_offset_ns, 90'000'000U);
  }
  EXPECT_EQ(d.imu_packets, 30U);
}

TEST(OusterRealData, LegacyAndLowDataCapturesMatchTheManualGeometry) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster");
  for (const std::string name : {"OS-1-32-G_v2.1.1_1024x10", "OS-0-128-U1_v2.3.0_1024x10"}) {
    SCOPED_TRACE(name);
    const auto m = load_ouster_metadata(dir / (name + ".json"));
    const Decoded d = decode_capture(dir / (name + ".pcap"), m);
    EXPECT_LT(d.max_xyz_error_m, 1e-3);
    EXPECT_EQ(d.totals.packets, 64U);
    ASSERT_EQ(d.scans.size(), 1U);
    EXPECT_GT(d.scans[0].points.size(), 1024U * m.pixels_per_column / 4);
  }
}

// The shared decode loop (as the tools and the daemon run it), lidar and IMU
// packets of one capture mixed, host times from the capture.
TEST(OusterRealData, DecodeStreamGivesThreeScansOnTheHostClock) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster");
  const auto m = load_ouster_metadata(dir / "OS-1-128_v2.3.0_1024x10.json");
  OusterDecoder decoder(m);
  EXPECT_EQ(decoder.packet_period_ns(), 1'562'500);  // 100 ms / 64 packets
  ScanAssemblerConfig config = assembler_config_for(decoder, decoder.packet_period_ns(), 0.0F);
  config.sequence_modulus = decoder.sequence_modulus();
  ScanAssembler assembler(config);
  std::vector<ScanStats> stats;
  std::vector<std::int64_t> starts;
  DecodeStream stream(decoder, assembler, [&](LidarScan& s) {
    stats.push_back(s.stats);
    starts.push_back(s.start_time_ns);
  });
  PcapReader reader(dir / "OS-1-128_v2.3.0_1024x10_lb_n3.pcap");
  UdpDatagram d;
  std::int64_t first_capture_ns = 0;
  while (reader.next(d)) {
    if (first_capture_ns == 0) first_capture_ns = d.capture_time_ns;
    stream.push(d.payload, d.capture_time_ns);
  }
  stream.finish();
  EXPECT_EQ(stream.counters().count(PacketStatus::ok), 192U);
  EXPECT_EQ(stream.counters().count(PacketStatus::auxiliary), 30U);
  EXPECT_EQ(stream.counters().total(), 222U);
  ASSERT_EQ(stats.size(), 3U);
  EXPECT_TRUE(stats[1].complete);
  EXPECT_EQ(stats[1].missing_packets, 0U);
  // Scan starts on the host clock, 100 ms apart, near the capture's time.
  EXPECT_NEAR(static_cast<double>(starts[2] - starts[1]), 100e6, 1e6);
  EXPECT_NEAR(static_cast<double>(starts[0] - first_capture_ns), 0.0, 50e6);
}

TEST(OusterRealData, CutRealPacketsAreTruncatedAndOthersForeign) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster");
  for (const std::string name : {"OS-1-32-G_v2.1.1_1024x10", "OS-0-128-U1_v2.3.0_1024x10"}) {
    SCOPED_TRACE(name);
    const auto m = load_ouster_metadata(dir / (name + ".json"));
    OusterDecoder decoder(m);
    PcapReader reader(dir / (name + ".pcap"));
    UdpDatagram d;
    int lidar = 0;
    while (reader.next(d)) {
      if (d.payload.size() != decoder.layout().packet_bytes) continue;
      ++lidar;
      for (const std::size_t cut : {std::size_t{12}, std::size_t{100}, d.payload.size() / 2, d.payload.size() - 1})
        EXPECT_EQ(decoder.decode(d.payload.first(cut), 0).status, PacketStatus::truncated) << cut;
    }
    EXPECT_EQ(lidar, 64);
  }
}

TEST(OusterRealData, ImuPacketsShowGravityAndAStillSensor) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster");
  const auto m = load_ouster_metadata(dir / "OS-0-128-U1_v2.3.0_1024x10.json");
  const Decoded d = decode_capture(dir / "OS-0-128-U1_v2.3.0_1024x10.pcap", m);
  ASSERT_EQ(d.imu.size(), 10U);
  for (std::size_t i = 0; i < d.imu.size(); ++i) {
    const auto& s = d.imu[i];
    const double g = std::hypot(s.accel_mps2[0], s.accel_mps2[1], s.accel_mps2[2]);
    // Units, not calibration: 1 g in m/s², not g. This unit's MEMS reads
    // 0.98-1.06 g at rest (raw values in the capture), hence 10 %.
    EXPECT_NEAR(g, 9.81, 1.0);
    EXPECT_LT(std::hypot(s.gyro_radps[0], s.gyro_radps[1], s.gyro_radps[2]), 0.1);
    if (i > 0) {
      EXPECT_GT(s.system_time_ns, d.imu[i - 1].system_time_ns);
    }
  }
}

}  // namespace
}  // namespace adit::drivers
