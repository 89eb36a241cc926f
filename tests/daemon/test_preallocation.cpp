// aditd's preallocations follow the configured sensor, not the busiest one
// (docs/decisions/032-aditd-memory.md): a VLP-16's scan, packet and odometry
// buffers are sized from its own packet rate and datagram, so a change that
// sizes them for any sensor again (4096 packets a scan, 64 kB a packet,
// slam's 400 000 points) fails here rather than in a resident-size figure.
#include <gtest/gtest.h>

#include <atomic>

#include "adit/config/config.hpp"
#include "adit/daemon/lidar_source.hpp"
#include "adit/daemon/pipeline_stats.hpp"
#include "adit/daemon/scan_odometry.hpp"
#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/velodyne.hpp"
#include "adit/drivers/lidar/velodyne_encoder.hpp"
#include "adit/drivers/pcap_writer.hpp"
#include "temp_file.hpp"

namespace adit::daemon {
namespace {

// The VLP-16 manual's packet rates: 754 packets/s in a single-return mode,
// 1508 in dual return; 12 blocks of 32 points a packet; at most 5 Hz.
constexpr double kVlp16DualPacketsPerS = 1508.0;
constexpr std::size_t kVlp16PointsPerPacket = 384;
// One revolution at 5 Hz in dual return, plus the assembler's two packets of margin.
constexpr auto kVlp16ScanPoints = static_cast<std::size_t>(0.2 * kVlp16DualPacketsPerS + 2) * kVlp16PointsPerPacket;

TEST(Preallocation, Vlp16ScanRoomIsOneDualReturnRevolutionAtFiveHertz) {
  const drivers::VelodyneDecoder decoder(drivers::VelodyneModel::vlp16,
                                         drivers::velodyne_nominal_calibration(drivers::VelodyneModel::vlp16));
  EXPECT_NEAR(1e9 / static_cast<double>(decoder.min_packet_period_ns()), kVlp16DualPacketsPerS, 2.0);
  EXPECT_EQ(decoder.max_packet_bytes(), drivers::kVelodyneDataPacketSize);
  const std::size_t room = drivers::assembler_config_for(decoder, 0, 0.0F).max_points_per_scan;
  EXPECT_EQ(room, kVlp16ScanPoints);
}

class PreallocationSource : public ::testing::Test {
 protected:
  PreallocationSource()
      : calibration(drivers::format_velodyne_calibration(
                        drivers::velodyne_nominal_calibration(drivers::VelodyneModel::vlp16)),
                    ".yaml"),
        pcap("", ".pcap") {
    drivers::PcapWriter{pcap.path()};  // an empty capture: the source opens it, nothing is read
    config.lidar.model = "VLP-16";
    config.lidar.source = config::LidarSource::pcap;
    config.lidar.pcap = pcap.path().string();
    config.lidar.calibration = calibration.path().string();
  }
  test::TempFile calibration;
  test::TempFile pcap;
  config::Config config;
  PipelineStats stats;
  std::atomic<bool> stop{false};
};

TEST_F(PreallocationSource, Vlp16PoolsHoldItsScanAndItsDatagram) {
  const LidarSource source(config, 0.0, 400'000, stats, stop);
  EXPECT_EQ(source.max_points_per_scan(), kVlp16ScanPoints);
  EXPECT_EQ(source.packet_bytes(), drivers::kVelodyneDataPacketSize + 1);
  // The odometry's buffers (its downsampler's table, the registration's
  // planes) are sized to the same scan, not to slam's default.
  const slam::OdometryConfig odometry = odometry_config_of(config, {}, source.max_points_per_scan());
  EXPECT_EQ(odometry.max_scan_points, kVlp16ScanPoints);
  EXPECT_LT(odometry.max_scan_points, slam::OdometryConfig{}.max_scan_points);
}

}  // namespace
}  // namespace adit::daemon
