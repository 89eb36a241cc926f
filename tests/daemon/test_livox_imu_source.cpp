// The Mid-360's own IMU wired into aditd (`imu.source: livox`): a simulated
// Mid-360 session (its IMU's SDK2 packets to port 56401 in lidar.pcap, among
// the points) replayed through LidarSource reaches the odometry's history as
// the odometry reads it (copy_covering per scan): every packet counted, the
// stamps on the LiDAR's clock and increasing at 200 Hz, the readings the
// simulated ones (float32 in g on the wire); the pipeline hands the same
// source to the odometry and records the IMU packets on their own port, and
// reads them live from a socket of their own. The Avia's IMU packets, among
// its points on the data port, reach it too.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>
#include <cmath>
#include <limits>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>

#include "adit/common/clock.hpp"
#include "adit/config/load.hpp"
#include "adit/daemon/lidar_source.hpp"
#include "adit/daemon/livox_imu.hpp"
#include "adit/daemon/pipeline.hpp"
#include "adit/drivers/lidar/livox.hpp"
#include "adit/drivers/lidar/livox_encoder.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "adit/drivers/pcap_replay.hpp"
#include "adit/drivers/udp.hpp"
#include "adit/drivers/pcap_writer.hpp"
#include "adit/sim/session.hpp"
#include "shared_data.hpp"
#include "pipeline_run.hpp"

namespace adit::daemon {
namespace {

// A 9 s walk through the building with a hand-held Mid-360 (simulated once per build tree).
const sim::SimOptions& session() {
  static const sim::SimOptions o = [] {
    sim::SimOptions s;
    s.scene = "building";
    s.platform = "handheld";
    s.sensor = "Mid-360";
    s.duration_s = 9.0;
    s.seed = 7;
    s.out = test::binary_dir() / "test-sessions" / "livox-imu-source";
    if (!std::filesystem::exists(s.out / "session.yaml")) sim::run_simulation(s);
    return s;
  }();
  return o;
}

std::size_t imu_datagrams(const std::filesystem::path& pcap) {
  drivers::PcapReader reader(pcap);
  drivers::UdpDatagram d;
  std::size_t n = 0;
  while (reader.next(d)) n += d.dst_port == drivers::kLivoxMid360ImuPort ? 1 : 0;
  return n;
}

TEST(LivoxImuSource, SessionReadsTheMid360sImuWhereTheSimulatorMountedIt) {
  const sim::SimOptions& o = session();
  const config::Config c = config::load_config(o.out / "session.yaml");
  ASSERT_TRUE(c.imu.enabled);
  EXPECT_EQ(c.imu.source, config::ImuSource::livox);
  EXPECT_FALSE(c.can.enabled);
  // One figure for the IMU inside the sensor: the simulator's mount is aditd's.
  const ImuMounting aditd = livox_imu_mounting(drivers::LivoxModel::mid360, c.lidar.extrinsics);
  const sim::ImuOptions simulated = sim::simulated_imu(o, sim::SimImuSource::livox);
  EXPECT_TRUE((simulated.mount.translation() - aditd.position_m).isZero(1e-9))
      << simulated.mount.translation().transpose() << " vs " << aditd.position_m.transpose();
  EXPECT_TRUE((simulated.mount.linear() - aditd.rotation).isZero(1e-12));
  for (int axis = 0; axis < 3; ++axis)
    EXPECT_NEAR(c.imu.position_m[static_cast<std::size_t>(axis)], aditd.position_m(axis), 1e-9);
}

TEST(LivoxImuSource, PcapReadingsReachTheOdometrysHistoryOnTheLidarClock) {
  const sim::SimOptions& o = session();
  config::Config c = config::load_config(o.out / "session.yaml");
  const std::vector<sim::ImuSample> truth =
      sim::simulate_imu(sim::simulated_path(sim::simulated_scene(o), o), sim::simulated_imu(o, sim::SimImuSource::livox));
  const std::size_t packets = imu_datagrams(c.lidar.pcap);
  ASSERT_EQ(packets, truth.size());

  PipelineStats stats;
  const std::atomic<bool> stop{false};
  LidarSource source(c, 0.0, 0, stats, stop);
  PacketImu* imu = source.imu();
  ASSERT_NE(imu, nullptr);
  EXPECT_STREQ(imu->imu_name(), "livox");
  source.start();
  // As the odometry stage reads it (scan_odometry.cpp): catch up past each
  // sweep, then the readings from the previous scan's start to the sweep's end.
  const auto keep_waiting = [] { return true; };
  std::vector<slam::ImuSample> covering;
  covering.reserve(kImuHistoryCapacity);
  std::vector<slam::ImuSample> readings;
  double previous = 0.0;
  std::size_t scans = 0;
  while (ScanSlot* slot = source.scans().take_or_wait(keep_waiting)) {
    const double t = 1e-9 * static_cast<double>(slot->scan.start_time_ns);
    imu->catch_up(t + 0.15, keep_waiting);
    imu->history().copy_covering(previous > 0.0 ? previous : t, t + 0.1, covering);
    for (const slam::ImuSample& s : covering)
      if (readings.empty() || s.t > readings.back().t) readings.push_back(s);
    previous = t;
    ++scans;
    source.scans().release(slot);
  }
  source.join();

  const ImuStats& s = imu->imu_stats();
  std::printf("%zu scans; %llu IMU packets, %llu readings (%llu unclocked) at %.1f Hz; the odometry copied %zu\n", scans,
              static_cast<unsigned long long>(s.packets.load()), static_cast<unsigned long long>(s.samples.load()),
              static_cast<unsigned long long>(s.count(ImuProblem::unclocked)), s.rate_hz.load(), readings.size());
  EXPECT_GE(scans, 85U);
  EXPECT_EQ(stats.foreign_datagrams.load(), 0U) << "port 56401 is the IMU's, not foreign";
  EXPECT_EQ(s.packets.load(), packets);
  // Every packet is a reading but those before the LiDAR's first packet (no clock yet).
  EXPECT_LE(s.count(ImuProblem::unclocked), 2U);
  EXPECT_EQ(s.samples.load() + s.count(ImuProblem::unclocked), packets);
  EXPECT_EQ(s.gyro_samples.load(), s.samples.load());
  EXPECT_EQ(s.count(ImuProblem::time_back) + s.count(ImuProblem::gap) + s.count(ImuProblem::undecodable), 0U);
  EXPECT_NEAR(s.rate_hz.load(), 200.0, 2.0);

  // The odometry saw (nearly) all of them, 5 ms apart, each the simulated
  // reading at its own time: the packet's stamp through the LiDAR stream's clock.
  ASSERT_GE(readings.size(), truth.size() - 40);  // all but the last sweep's tail
  const double start_s = 1e-9 * static_cast<double>(o.start_time_ns);
  double worst_accel = 0.0, worst_gyro = 0.0;
  double late_min = 1.0, late_max = -1.0;
  for (std::size_t i = 0; i < readings.size(); ++i) {
    const slam::ImuSample& r = readings[i];
    if (i > 0) {
      EXPECT_NEAR(r.t - readings[i - 1].t, 0.005, 1e-5) << i;
    }
    const auto k = static_cast<std::size_t>(std::llround((r.t - start_s) * 200.0));
    ASSERT_LT(k, truth.size());
    const sim::ImuSample& expected = truth[k];
    const double late = r.t - (start_s + expected.stamp);
    late_min = std::min(late_min, late);
    late_max = std::max(late_max, late);
    worst_accel = std::max(worst_accel, (r.specific_force - expected.accel).cwiseAbs().maxCoeff());
    worst_gyro = std::max(worst_gyro, (r.angular_rate - expected.gyro).cwiseAbs().maxCoeff());
    EXPECT_TRUE(r.has_gyro);
  }
  // On the points' own clock: the stream's offset (a packet's capture minus
  // its first point's stamp: 96 points over 0.48 ms, then 0.1 ms on the wire)
  // shifts the IMU exactly as it shifts the scans, to the double's 0.24 µs at 1.8e9 s.
  const double offset_s = 1e-9 * static_cast<double>(stats.clock_offset_ns.load());
  EXPECT_NEAR(offset_s, 0.00058, 1e-5);
  EXPECT_NEAR(late_min, offset_s, 1e-6);
  EXPECT_NEAR(late_max, offset_s, 1e-6);
  EXPECT_LT(worst_accel, 1e-5);   // float32 g × 9.80665
  EXPECT_LT(worst_gyro, 1e-6);    // float32 rad/s
}

// The Avia sends its IMU's SDK1 packets among its points, to the data port:
// those the decoder reports `auxiliary` reach the LivoxImu, in the body's axes
// (the LiDAR turned 90° left), placed at the Avia's IMU; a cut IMU packet is a
// bad packet of the stream, not a reading.
TEST(LivoxImuSource, AviaImuPacketsAmongItsPointsReachTheImu) {
  const std::filesystem::path pcap = test::binary_dir() / "test-sessions" / "avia-imu.pcap";
  std::filesystem::create_directories(pcap.parent_path());
  constexpr std::int64_t kStart = 1'767'225'600'000'000'000;
  constexpr std::int64_t kPacketNs = 96 * 4167;  // 96 records, one every 4 167 ns
  std::size_t imu_packets = 0;
  {
    drivers::PcapWriter writer(pcap);
    drivers::UdpEndpoints to_data_port;
    to_data_port.src_port = to_data_port.dst_port = drivers::kLivoxAviaDataPort;
    std::array<drivers::LivoxRawPoint, 96> points{};
    for (std::size_t i = 0; i < points.size(); ++i) points[i] = {5000 + static_cast<std::int32_t>(i), 100, 200, 50, 0};
    std::vector<std::uint8_t> bytes(drivers::kLivoxSdk1PointPacketBytes);
    std::vector<std::uint8_t> imu(drivers::kLivoxSdk1ImuPacketBytes);
    const float gyro[3] = {0.01F, -0.02F, 0.3F};
    const float accel_g[3] = {0.0F, 0.1F, 1.0F};
    std::int64_t next_imu = kStart;
    for (std::int64_t t = kStart; t < kStart + 1'000'000'000; t += kPacketNs) {
      drivers::encode_livox_sdk1_points(t, false, points, bytes);
      writer.write_udp(t + kPacketNs + 100'000, to_data_port, bytes);
      for (; next_imu <= t; next_imu += 5'000'000, ++imu_packets) {
        drivers::encode_livox_sdk1_imu(next_imu, gyro, accel_g, imu);
        writer.write_udp(next_imu + 100'000, to_data_port, imu);
      }
    }
    writer.write_udp(kStart + 1'000'000'000, to_data_port, std::span(imu).first(imu.size() - 1));  // cut
    writer.flush();
  }
  config::Config c;
  c.lidar.model = "Avia";
  c.lidar.source = config::LidarSource::pcap;
  c.lidar.pcap = pcap.string();
  c.lidar.replay_speed = 0.0;
  c.lidar.extrinsics.rpy_deg = {0.0, 0.0, 90.0};
  c.imu.enabled = true;
  c.imu.source = config::ImuSource::livox;
  PipelineStats stats;
  const std::atomic<bool> stop{false};
  LidarSource source(c, 0.0, 0, stats, stop);
  PacketImu* imu = source.imu();
  ASSERT_NE(imu, nullptr);
  EXPECT_TRUE(imu->mounting().position_m.isApprox(Eigen::Vector3d(0.02326, -0.04165, 0.0284), 1e-9))
      << imu->mounting().position_m.transpose();  // the Avia's IMU (-41.65, -23.26, 28.4) mm turned by 90°
  source.start();
  while (ScanSlot* slot = source.scans().take_or_wait([] { return true; })) source.scans().release(slot);
  source.join();
  imu->catch_up(1e30, {});
  const ImuStats& s = imu->imu_stats();
  EXPECT_EQ(s.packets.load(), imu_packets);
  EXPECT_EQ(s.samples.load() + s.count(ImuProblem::unclocked), imu_packets);
  EXPECT_LE(s.count(ImuProblem::unclocked), 1U);
  EXPECT_EQ(stats.bad_packets.load(), 1U) << "the cut IMU packet";
  EXPECT_GE(stats.scans.load(), 9U);
  const auto mean = imu->history().mean(imu->history().latest() - 0.5, imu->history().latest());
  ASSERT_TRUE(mean);
  EXPECT_NEAR(mean->x(), -0.1 * 9.80665, 1e-5);  // 0.1 g along the sensor's y: the body's −x
  EXPECT_NEAR(mean->y(), 0.0, 1e-5);
  EXPECT_NEAR(mean->z(), 9.80665, 1e-5);
}

TEST(LivoxImuSource, PipelineFeedsTheOdometryAndRecordsTheImuPort) {
  const sim::SimOptions& o = session();
  config::Config c = config::load_config(o.out / "session.yaml");
  c.lidar.replay_speed = 0.0;
  c.threads.lock_memory = false;
  const std::filesystem::path state = test::binary_dir() / "livox-imu-pipeline";
  c.payload.state_dir = state.string();
  PipelineOptions options;
  options.mapping = false;
  options.record_file = state / "lidar.pcap";
  Pipeline pipeline(c, options);
  pipeline.start();
  pipeline.join();
  const PipelineStats& s = pipeline.stats();
  const std::size_t packets = imu_datagrams(c.lidar.pcap);
  EXPECT_EQ(s.imu.packets.load(), packets) << "the odometry's IMU is the Livox's";
  EXPECT_GE(s.imu.samples.load() + 2, packets);
  EXPECT_GE(s.poses.load(), 85U);
  EXPECT_EQ(imu_datagrams(options.record_file), packets);
}

// Live: the session's first 2 s sent over real UDP on loopback at their own
// pace, the points to lidar.port and the IMU's packets to lidar.imu_port (both
// off 56301/56401, so that tests running side by side do not meet): the second
// socket reads every IMU packet, stamped on the LiDAR clock mapped to the host's.
TEST(LivoxImuSource, ArrivesLiveOnItsOwnPortBesideThePoints) {
  const sim::SimOptions& o = session();
  const auto lidar_port = static_cast<std::uint16_t>(40000 + 2 * (::getpid() % 10000));
  const auto imu_port = static_cast<std::uint16_t>(lidar_port + 1);
  const std::string yaml = fmt::format(
      "payload:\n  id: test\n  state_dir: {}\nlidar:\n  model: Mid-360\n  source: udp\n  address: 127.0.0.1\n"
      "  port: {}\n  imu_port: {}\nimu:\n  enabled: true\n  source: livox\nthreads:\n  lock_memory: false\n",
      (test::binary_dir() / "livox-imu-live").string(), lidar_port, imu_port);
  const std::unique_ptr<Pipeline> pipeline = test::live_pipeline(yaml);
  // Sent once the receiver reads (it drains what came before the session).
  ASSERT_TRUE(test::start_and_wait_for_receiver(*pipeline));
  drivers::UdpSender to_lidar("127.0.0.1", lidar_port);
  drivers::UdpSender to_imu("127.0.0.1", imu_port);
  drivers::PacedPcapReader reader(o.out / "lidar.pcap", 1.0);
  drivers::UdpDatagram d;
  std::size_t imu_sent = 0, lidar_sent = 0;
  while (reader.next(d) && d.capture_time_ns < o.start_time_ns + 2'000'000'000) {
    if (d.dst_port == drivers::kLivoxMid360ImuPort) imu_sent += to_imu.send(d.payload) ? 1 : 0;
    else lidar_sent += to_lidar.send(d.payload) ? 1 : 0;
  }
  const double sent_s = 1e-9 * static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                                       std::chrono::system_clock::now().time_since_epoch())
                                                       .count());
  for (int i = 0; i < 200 && pipeline->stats().datagrams.load() < imu_sent + lidar_sent; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  pipeline->end_source();
  pipeline->join();
  const ImuStats& imu = pipeline->stats().imu;
  std::printf("live: %zu point and %zu IMU datagrams sent; %llu IMU packets read, %llu readings (%llu unclocked)\n",
              lidar_sent, imu_sent, static_cast<unsigned long long>(imu.packets.load()),
              static_cast<unsigned long long>(imu.samples.load()),
              static_cast<unsigned long long>(imu.count(ImuProblem::unclocked)));
  EXPECT_NEAR(static_cast<double>(imu_sent), 400.0, 1.0);
  EXPECT_EQ(imu.packets.load(), imu_sent) << "loopback does not lose 400 datagrams";
  EXPECT_EQ(imu.samples.load() + imu.count(ImuProblem::unclocked), imu.packets.load());
  EXPECT_GE(imu.samples.load() + 2, imu_sent);
  EXPECT_EQ(imu.count(ImuProblem::time_back), 0U);
  // Live, a busy machine's odometry drops scans (counted): how many it keeps is not this test's matter.
  EXPECT_GT(pipeline->stats().poses.load(), 0U);
  // Stamped on the LiDAR clock mapped to the host's: the last reading within the sending's last 0.1 s.
  EXPECT_NEAR(imu.last_t.load(), sent_s, 0.1);
}

}  // namespace
}  // namespace adit::daemon
