// The Velodyne decoder against clouds decoded independently from the same
// captures (../shared/data/lidar/velodyne-*/reference-*.pcd with the settings
// in reference-settings.yaml), and the HDL-32E capture's timing and position packets.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <numbers>

#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/scan_files.hpp"
#include "adit/drivers/lidar/velodyne.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "cloud_match.hpp"
#include "shared_data.hpp"

namespace adit::drivers {
namespace {

constexpr float kTolerance = 0.002F;  // 2 mm

struct Decoded {
  std::vector<LidarScan> scans;
  PacketCounters counters;
  ScanAssemblerTotals totals;
  std::optional<VelodynePosition> position;
  std::optional<ClockEstimate> clock;
  double packet_rate_hz = 0.0;  // data packets over their sensor time span
  double degrees_per_ms = 0.0;  // rotation rate from the first block azimuths of consecutive packets
};

Decoded decode_capture(const std::filesystem::path& dir, VelodyneModel model, const std::string& calibration,
                       float cut_deg, VelodyneDecoderConfig config = {}) {
  VelodyneDecoder decoder(model, load_velodyne_calibration(dir / calibration), config);
  PcapReader reader(dir / "capture.pcap");
  UdpDatagram d;
  // The return mode decides the packet period: peek at the first data packet.
  VelodyneReturnMode mode = VelodyneReturnMode::strongest;
  {
    PcapReader peek(dir / "capture.pcap");
    while (peek.next(d)) {
      if (const auto m = velodyne_return_mode_from_packet(d.payload)) {
        mode = *m;
        break;
      }
    }
  }
  ScanAssembler assembler(assembler_config_for(decoder, velodyne_packet_period_ns(model, mode), cut_deg));
  Decoded out;
  DecodeStream stream(decoder, assembler, [&](LidarScan& scan) { out.scans.push_back(scan); });
  std::int64_t first_ns = 0, last_ns = 0, data_packets = 0;
  double degrees = 0.0;
  int previous_azimuth = -1;
  while (reader.next(d)) {
    if (stream.push(d.payload, d.capture_time_ns) != PacketStatus::ok) continue;
    const int azimuth = d.payload[2] | d.payload[3] << 8;
    if (previous_azimuth >= 0) degrees += ((azimuth - previous_azimuth + 36000) % 36000) / 100.0;
    previous_azimuth = azimuth;
    last_ns = stream.last_sensor_time_ns();
    if (data_packets++ == 0) first_ns = last_ns;
  }
  stream.finish();
  out.packet_rate_hz = (data_packets - 1) * 1e9 / static_cast<double>(last_ns - first_ns);
  out.degrees_per_ms = degrees / ((last_ns - first_ns) / 1e6);
  out.counters = stream.counters();
  out.totals = assembler.totals();
  out.position = decoder.last_position();
  out.clock = stream.clock().estimate();
  return out;
}

struct Settings {
  float min_range, max_range, sector_min, sector_max, phase;
};

Settings read_settings(const std::filesystem::path& dir) {
  const YAML::Node s = YAML::LoadFile((dir / "reference-settings.yaml").string());
  return {s["min_range_m"].as<float>(), s["max_range_m"].as<float>(), s["cloud_min_angle_deg"].as<float>(),
          s["cloud_max_angle_deg"].as<float>(), s["scan_phase_deg"].as<float>()};
}

std::vector<test::Xyz> reference_cloud(const std::filesystem::path& dir) {
  std::vector<CloudPoint> cloud;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().filename().string().starts_with("reference-") && entry.path().extension() == ".pcd") {
      read_pcd(entry.path(), cloud);
    }
  }
  std::vector<test::Xyz> out;
  for (const CloudPoint& p : cloud) out.push_back({p.x, p.y, p.z});
  return out;
}

// Velodyne azimuth of a point (clockwise from x, degrees in [0, 360)).
float azimuth_deg(const LidarPoint& p) {
  float a = std::atan2(-p.y, p.x) * 180.0F / std::numbers::pi_v<float>;
  return a < 0 ? a + 360.0F : a;
}

bool in_sector(float a, float lo, float hi) { return lo <= hi ? (a >= lo && a <= hi) : (a >= lo || a <= hi); }

std::vector<test::Xyz> all_points(const Decoded& decoded) {
  std::vector<test::Xyz> out;
  for (const LidarScan& scan : decoded.scans) {
    for (const LidarPoint& p : scan.points) out.push_back({p.x, p.y, p.z});
  }
  return out;
}

double max_rot_correction_deg(const std::filesystem::path& calibration) {
  double most = 0.0;
  for (const VelodyneLaser& l : load_velodyne_calibration(calibration).lasers) most = std::max(most, std::abs(l.rot_correction));
  return most * 180.0 / std::numbers::pi;
}

// Both criteria of the issue. The reference is one scan cut by its decoder;
// as the data README says, scan cuts may differ, so (1) every reference point
// must have a decoded point of the capture within 2 mm, and (2) of the points
// of our scan that covers the reference best, inside its sector and range,
// ≥ 99.9% must have a reference point within 2 mm. The reference decoder selects the sector by block
// azimuth, before the per-laser rotational correction, so points within that
// correction (+1°) of the sector's edges are left out of (2).
void expect_matches_reference(const std::filesystem::path& dir, VelodyneModel model, const std::string& calibration) {
  const Settings settings = read_settings(dir);
  VelodyneDecoderConfig config;
  config.min_range_m = settings.min_range;
  config.max_range_m = settings.max_range;
  config.azimuth_model = VelodyneAzimuthModel::reference_decoders;
  const Decoded decoded = decode_capture(dir, model, calibration, settings.phase, config);
  const std::vector<test::Xyz> reference = reference_cloud(dir);
  ASSERT_FALSE(reference.empty());
  const std::vector<test::Xyz> ours = all_points(decoded);
  const test::PointGrid our_grid(ours, kTolerance);
  std::size_t reference_matched = 0;
  for (const test::Xyz& r : reference) reference_matched += our_grid.has_within(r, kTolerance) ? 1 : 0;
  EXPECT_EQ(reference_matched, reference.size()) << "reference points without a decoded point within 2 mm: "
                                                  << reference.size() - reference_matched << " of " << reference.size();

  // Our scan that covers the reference best.
  std::size_t best = 0;
  std::size_t best_count = 0;
  for (std::size_t i = 0; i < decoded.scans.size(); ++i) {
    std::vector<test::Xyz> xyz;
    for (const LidarPoint& p : decoded.scans[i].points) xyz.push_back({p.x, p.y, p.z});
    const test::PointGrid grid(xyz, kTolerance);
    std::size_t count = 0;
    for (const test::Xyz& r : reference) count += grid.has_within(r, kTolerance) ? 1 : 0;
    if (count > best_count) {
      best_count = count;
      best = i;
    }
  }
  const test::PointGrid reference_grid(reference, kTolerance);
  const float margin = static_cast<float>(max_rot_correction_deg(dir / calibration)) + 1.0F;
  const float lo = settings.sector_min + margin;
  const float hi = settings.sector_max - margin;
  std::size_t considered = 0;
  std::size_t considered_matched = 0;
  for (const LidarPoint& p : decoded.scans[best].points) {
    if (!in_sector(azimuth_deg(p), lo < 0 ? lo + 360 : lo, hi >= 360 ? hi - 360 : hi)) continue;
    if (p.range_m <= settings.min_range + kTolerance || p.range_m >= settings.max_range - kTolerance) continue;
    ++considered;
    considered_matched += reference_grid.has_within({p.x, p.y, p.z}, kTolerance) ? 1 : 0;
  }
  ASSERT_GT(considered, reference.size() / 2);
  const double fraction = static_cast<double>(considered_matched) / static_cast<double>(considered);
  EXPECT_GE(fraction, 0.999) << considered_matched << " of " << considered << " decoded points matched";
  std::printf("%s: reference %zu/%zu matched; ours %zu/%zu matched (%.5f)\n", dir.filename().c_str(),
              reference_matched, reference.size(), considered_matched, considered, fraction);
}

TEST(VelodyneRealdata, Vlp16DualMatchesTheReferenceCloud) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-vlp16-dual");
  expect_matches_reference(dir, VelodyneModel::vlp16, "VLP16.yaml");
}

TEST(VelodyneRealdata, Vlp32cMatchesTheReferenceCloud) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-vlp32c");
  expect_matches_reference(dir, VelodyneModel::vlp32c, "VLP32.yaml");
}

}  // namespace
}  // namespace adit::drivers

namespace adit::drivers {
namespace {

// The manual's azimuth model on the same capture: every reference point has a
// point of the same ring and range (within 2 mm) whose azimuth differs by less
// than one block step (0.4° at 10 Hz): the reference decoder's quirks move
// points by at most that (see VelodyneAzimuthModel).
TEST(VelodyneRealdata, Vlp16DualManualAzimuthsStayWithinOneBlockOfTheReference) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-vlp16-dual");
  const Settings settings = read_settings(dir);
  const Decoded decoded = decode_capture(dir, VelodyneModel::vlp16, "VLP16.yaml", 0.0F,
                                         {settings.min_range, settings.max_range, VelodyneAzimuthModel::manual});
  std::map<std::pair<int, long>, std::vector<float>> by_ring_and_range;
  for (const LidarScan& scan : decoded.scans) {
    for (const LidarPoint& p : scan.points) {
      by_ring_and_range[{p.ring, std::lround(p.range_m / 0.002F)}].push_back(azimuth_deg(p));
    }
  }
  std::vector<std::uint8_t> bytes;
  std::vector<CloudPoint> unused;
  std::size_t matched = 0;
  std::size_t total = 0;
  float worst = 0.0F;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".pcd") continue;
    // Fields: x y z intensity return_type channel azimuth(rad) elevation distance time_stamp, 32 bytes.
    std::ifstream in(entry.path(), std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t data = text.find("DATA binary\n") + 12;
    for (std::size_t at = data; at + 32 <= text.size(); at += 32) {
      std::uint16_t channel;
      float azimuth_rad, distance;
      std::memcpy(&channel, text.data() + at + 14, 2);
      std::memcpy(&azimuth_rad, text.data() + at + 16, 4);
      std::memcpy(&distance, text.data() + at + 24, 4);
      const float azimuth = azimuth_rad * 180.0F / std::numbers::pi_v<float>;
      float nearest = 360.0F;
      for (long r = std::lround(distance / 0.002F) - 1; r <= std::lround(distance / 0.002F) + 1; ++r) {
        const auto it = by_ring_and_range.find({channel, r});
        if (it == by_ring_and_range.end()) continue;
        for (const float a : it->second) {
          const float d = std::abs(std::remainder(a - azimuth, 360.0F));
          nearest = std::min(nearest, d);
        }
      }
      ++total;
      if (nearest <= 0.45F) {
        ++matched;
        worst = std::max(worst, nearest);
      }
    }
  }
  ASSERT_GT(total, 10000u);
  EXPECT_EQ(matched, total);
  std::printf("manual azimuths: %zu/%zu within one block step, largest difference %.3f deg\n", matched, total, worst);
}

// The VLP-32C capture comes from a sensor set to send only 270°..90°: each
// packet that reaches 90° jumps to 270° inside itself. The decoder times the
// firings after the jump by the rotation rate, the assembler cuts there and
// does not count the skipped half turn as lost packets.
TEST(VelodyneRealdata, Vlp32cFieldOfViewGapsAreNeitherLossNorBrokenScans) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-vlp32c");
  const Decoded decoded = decode_capture(dir, VelodyneModel::vlp32c, "VLP32.yaml", 180.0F);
  EXPECT_EQ(decoded.totals.missing_packets, 0u);
  std::vector<const LidarScan*> complete;
  for (const LidarScan& scan : decoded.scans) {
    if (scan.stats.complete) complete.push_back(&scan);
  }
  ASSERT_GE(complete.size(), 3u);
  for (std::size_t i = 1; i < complete.size(); ++i) {
    const double period_ms = (complete[i]->sensor_start_time_ns - complete[i - 1]->sensor_start_time_ns) / 1e6;
    EXPECT_NEAR(period_ms, 100.0, 1.0);  // 600 rpm; the gap's length is estimated to ~1%
  }
}

TEST(VelodyneRealdata, Hdl32eTimingAndPositionPackets) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-hdl32e");
  const Decoded decoded = decode_capture(dir, VelodyneModel::hdl32e, "HDL32.yaml", 0.0F);
  EXPECT_EQ(decoded.counters.count(PacketStatus::ok), 876u);
  EXPECT_EQ(decoded.counters.count(PacketStatus::auxiliary), 100u);
  EXPECT_EQ(decoded.counters.total(), 976u);

  // The first sentence is $GPRMC,220243,A,3708.5809,N,12139.7813,W,028.8,158.3,111212,... (2012-12-11
  // 22:02:43 UTC) and the vehicle moves at 28.8 knots; the last one is at most a second later.
  ASSERT_TRUE(decoded.position.has_value());
  ASSERT_TRUE(decoded.position->rmc.has_value());
  EXPECT_TRUE(decoded.position->rmc->valid);
  EXPECT_GE(decoded.position->rmc->utc_ns, 1'355'263'363'000'000'000);
  EXPECT_LE(decoded.position->rmc->utc_ns, 1'355'263'365'000'000'000);
  EXPECT_NEAR(decoded.position->rmc->latitude_deg, 37.0 + 8.5809 / 60.0, 0.001);
  EXPECT_NEAR(decoded.position->rmc->longitude_deg, -(121.0 + 39.7813 / 60.0), 0.001);
  EXPECT_NEAR(decoded.position->rmc->speed_mps, 28.8 * 1852.0 / 3600.0, 1.0);
  // The position packet's µs timestamp agrees with the NMEA second it carries.
  EXPECT_NEAR(decoded.position->us_past_hour / 1e6, std::fmod(decoded.position->rmc->utc_ns / 1e9, 3600.0), 1.0);

  // Packets every 12 × 46.08 µs (HDL-32E manual): the time-based loss count finds none missing.
  EXPECT_EQ(decoded.totals.missing_packets, 0u);
  EXPECT_EQ(decoded.totals.duplicate_packets + decoded.totals.out_of_order_packets, 0u);
  EXPECT_NEAR(decoded.packet_rate_hz, 1e9 / velodyne_packet_period_ns(VelodyneModel::hdl32e, VelodyneReturnMode::strongest),
              2.0);
  // Scans: the period between complete scans matches the rotation rate measured independently from
  // the block azimuths (this unit turns at ~703 rpm, 11.7 Hz, not the default 600 rpm), steady to
  // 1%, each holding one period of packets.
  std::vector<const LidarScan*> complete;
  for (const LidarScan& scan : decoded.scans) {
    if (scan.stats.complete) complete.push_back(&scan);
  }
  ASSERT_GE(complete.size(), 3u);
  const double revolution_ms = 360.0 / decoded.degrees_per_ms;
  for (std::size_t i = 1; i < complete.size(); ++i) {
    const double period_ms = (complete[i]->sensor_start_time_ns - complete[i - 1]->sensor_start_time_ns) / 1e6;
    EXPECT_NEAR(period_ms, revolution_ms, revolution_ms * 0.01);
    EXPECT_NEAR(complete[i - 1]->stats.packets, period_ms * decoded.packet_rate_hz / 1e3, 2.0);
  }
  std::printf("HDL-32E: %.1f packets/s, scans at %.2f Hz\n", decoded.packet_rate_hz, 1e3 / revolution_ms);
  // Sensor time is GPS time: resolved to the NMEA hour, within a second or two of the capture clock.
  ASSERT_TRUE(decoded.clock.has_value());
  EXPECT_LT(std::abs(decoded.clock->offset_ns), 2'000'000'000) << decoded.clock->offset_ns;
  std::printf("HDL-32E: %zu complete scans, host-sensor offset %.3f ms\n", complete.size(), decoded.clock->offset_ns / 1e6);
}

}  // namespace
}  // namespace adit::drivers
