// The Ouster's IMU on real captures: drivers::decode_ouster_imu against a
// parse of the same bytes written here from the sensor manual's LEGACY IMU
// packet layout ("IMU Data Format": 48 bytes, little-endian: u64 system
// timestamp ns, u64 accelerometer timestamp ns, u64 gyroscope timestamp ns,
// 3 × f32 acceleration in g, 3 × f32 angular velocity in deg/s), and the
// readings reaching the daemon's pipeline with `imu.source: ouster`.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>

#include "adit/common/clock.hpp"
#include "adit/config/load.hpp"
#include "adit/daemon/pipeline.hpp"
#include "adit/drivers/lidar/ouster_packet.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "adit/drivers/pcap_replay.hpp"
#include "adit/drivers/udp.hpp"
#include "shared_data.hpp"
#include "pipeline_run.hpp"

namespace adit::daemon {
namespace {

static_assert(std::endian::native == std::endian::little, "the manual's layout is read with memcpy");

// The manual's layout, field by field.
struct ManualImuPacket {
  std::uint64_t system_ns = 0;
  std::uint64_t accel_ns = 0;
  std::uint64_t gyro_ns = 0;
  float accel_g[3] = {};
  float gyro_dps[3] = {};
};

ManualImuPacket manual_parse(std::span<const std::uint8_t> b) {
  ManualImuPacket p;
  std::memcpy(&p.system_ns, b.data() + 0, 8);
  std::memcpy(&p.accel_ns, b.data() + 8, 8);
  std::memcpy(&p.gyro_ns, b.data() + 16, 8);
  std::memcpy(p.accel_g, b.data() + 24, 12);
  std::memcpy(p.gyro_dps, b.data() + 36, 12);
  return p;
}

struct Capture {
  const char* pcap;
  const char* metadata;
  const char* model;      // lidar.model
  std::size_t packets;    // IMU packets on port 7503
  double mean_norm_g;     // computed once from the manual parse, kept to ±0.005 g
  double max_gyro_dps;    // the largest |axis|, kept to ±0.05 °/s
};

const Capture kCaptures[] = {
    {"OS-1-128_v2.3.0_1024x10_lb_n3.pcap", "OS-1-128_v2.3.0_1024x10.json", "OS1-128", 30, 1.087, 6.32},
    {"OS-0-128-U1_v2.3.0_1024x10.pcap", "OS-0-128-U1_v2.3.0_1024x10.json", "OS0-128", 10, 1.029, 1.46},
};

TEST(OusterImuRealData, DecodesAsTheManualsLayoutReadsTheSameBytes) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster");
  for (const Capture& c : kCaptures) {
    SCOPED_TRACE(c.pcap);
    drivers::PcapReader reader(dir / c.pcap);
    drivers::UdpDatagram d;
    std::size_t n = 0;
    double norm_sum = 0.0;
    double max_gyro = 0.0;
    ManualImuPacket previous;
    while (reader.next(d)) {
      if (d.dst_port != 7503) continue;
      ++n;
      ASSERT_EQ(d.payload.size(), drivers::kOusterImuPacketBytes);
      const ManualImuPacket m = manual_parse(d.payload);
      drivers::OusterImuSample s;
      ASSERT_TRUE(drivers::decode_ouster_imu(d.payload, s));
      EXPECT_EQ(s.system_time_ns, m.system_ns);
      EXPECT_EQ(s.accel_time_ns, m.accel_ns);
      EXPECT_EQ(s.gyro_time_ns, m.gyro_ns);
      for (int i = 0; i < 3; ++i) {
        EXPECT_FLOAT_EQ(s.accel_mps2[i], m.accel_g[i] * 9.80665F) << i;
        EXPECT_NEAR(s.gyro_radps[i], m.gyro_dps[i] * 3.14159265358979 / 180.0, 1e-6) << i;
        max_gyro = std::max(max_gyro, static_cast<double>(std::abs(m.gyro_dps[i])));
      }
      norm_sum += std::sqrt(static_cast<double>(m.accel_g[0]) * m.accel_g[0] +
                            static_cast<double>(m.accel_g[1]) * m.accel_g[1] +
                            static_cast<double>(m.accel_g[2]) * m.accel_g[2]);
      if (n > 1) {  // every clock advances
        EXPECT_GT(m.system_ns, previous.system_ns) << "packet " << n;
        EXPECT_GT(m.accel_ns, previous.accel_ns) << "packet " << n;
        EXPECT_GT(m.gyro_ns, previous.gyro_ns) << "packet " << n;
      }
      previous = m;
    }
    ASSERT_EQ(n, c.packets);
    const double mean_norm = norm_sum / static_cast<double>(n);
    EXPECT_NEAR(mean_norm, c.mean_norm_g, 0.005);
    EXPECT_NEAR(max_gyro, c.max_gyro_dps, 0.05);
    fmt::print("{}: {} IMU packets, mean |a| {:.4f} g, largest gyro axis {:.3f} deg/s\n", c.pcap, n, mean_norm, max_gyro);
    // Wrong sizes are refused, not read.
    std::vector<std::uint8_t> longer(drivers::kOusterImuPacketBytes + 1, 0);
    drivers::OusterImuSample s;
    EXPECT_FALSE(drivers::decode_ouster_imu(longer, s));
    EXPECT_FALSE(drivers::decode_ouster_imu(std::span<const std::uint8_t>(longer).first(47), s));
  }
}

TEST(OusterImuRealData, ReachesThePipelineOnTheLidarClock) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster");
  for (const Capture& c : kCaptures) {
    SCOPED_TRACE(c.pcap);
    const auto state = test::binary_dir() / "ouster-imu-test";
    const std::string yaml = fmt::format(
        "payload:\n  id: test\n  state_dir: {}\nlidar:\n  model: {}\n  source: pcap\n  pcap: {}\n"
        "  calibration: {}\n  replay_speed: 0\n  extrinsics:\n    rpy_deg: [0, 0, 90]\n"
        "imu:\n  enabled: true\n  source: ouster\nthreads:\n  lock_memory: false\n",
        state.string(), c.model, (dir / c.pcap).string(), (dir / c.metadata).string());
    const config::Config config = config::parse_config(yaml, "test.yaml", "/");
    PipelineOptions options;
    options.mapping = false;
    options.record_file = state / "lidar.pcap";  // the session's raw recording
    Pipeline pipeline(config, options);
    pipeline.start();
    pipeline.join();
    const PipelineStats& s = pipeline.stats();
    // The raw recording keeps the IMU's packets on their own port, byte for byte.
    {
      drivers::PcapReader original(dir / c.pcap);
      drivers::PcapReader recorded(options.record_file);
      std::vector<std::vector<std::uint8_t>> imu_in;
      std::vector<std::vector<std::uint8_t>> imu_out;
      drivers::UdpDatagram d;
      while (original.next(d))
        if (d.dst_port == 7503) imu_in.emplace_back(d.payload.begin(), d.payload.end());
      std::size_t all = 0;
      while (recorded.next(d)) {
        ++all;
        if (d.dst_port == 7503) imu_out.emplace_back(d.payload.begin(), d.payload.end());
      }
      EXPECT_EQ(all, s.recorded_datagrams.load());
      EXPECT_EQ(imu_out, imu_in);
    }
    const ImuStats& imu = s.imu;
    fmt::print("{}: {} IMU packets, {} readings ({} before the LiDAR's clock), {:.1f} Hz, clock spread {:.6f} s; {} scans\n",
               c.pcap, imu.packets.load(), imu.samples.load(), imu.count(ImuProblem::unclocked), imu.rate_hz.load(),
               imu.clock_spread_s.load(), s.scans.load());
    EXPECT_EQ(imu.packets.load(), c.packets);
    EXPECT_EQ(s.foreign_datagrams.load(), 0U) << "the IMU port is no longer foreign";
    // Every packet is a reading, but those before the LiDAR's first packet (no clock to stamp them on yet).
    EXPECT_EQ(imu.samples.load() + imu.count(ImuProblem::unclocked), c.packets);
    EXPECT_LE(imu.count(ImuProblem::unclocked), 1U);
    EXPECT_EQ(imu.gyro_samples.load(), imu.samples.load());
    EXPECT_EQ(imu.count(ImuProblem::time_back) + imu.count(ImuProblem::gap) + imu.count(ImuProblem::undecodable), 0U);
    EXPECT_NEAR(imu.rate_hz.load(), 100.0, 2.0);
    EXPECT_GE(s.scans.load(), 1U);
    // Stamped on the LiDAR's clock (capture time, 2022), not the sensor's (seconds since boot).
    EXPECT_GT(imu.last_t.load(), 1.6e9);
    // The IMU packets leave the sensor about 17 ms sooner after their stamps
    // than the LiDAR packets do (-16.8 ms on both captures): why the IMU is
    // stamped by its own accel_time_ns through the LiDAR's clock estimate,
    // not by its packets' arrival.
    EXPECT_TRUE(std::isfinite(imu.clock_spread_s.load()));
    EXPECT_LT(std::abs(imu.clock_spread_s.load()), 0.05);
  }
}

TEST(OusterImuRealData, ArrivesLiveOnItsOwnPortBesideTheLidar) {
  // The OS-1-128 capture sent over real UDP on loopback, the LiDAR's packets
  // to lidar.port and the IMU's to the metadata's udp_port_imu (both moved
  // off 7502/7503 so that tests running side by side do not meet).
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/ouster");
  const Capture& c = kCaptures[0];
  const auto lidar_port = static_cast<std::uint16_t>(20000 + 2 * (::getpid() % 10000));
  const auto imu_port = static_cast<std::uint16_t>(lidar_port + 1);
  std::ifstream in(dir / c.metadata);
  std::stringstream text;
  text << in.rdbuf();
  std::string json = text.str();
  const std::string key = "\"udp_port_imu\": 7503";
  ASSERT_NE(json.find(key), std::string::npos);
  json.replace(json.find(key), key.size(), fmt::format("\"udp_port_imu\": {}", imu_port));
  const auto metadata = test::binary_dir() / fmt::format("ouster-imu-live-{}.json", ::getpid());
  std::ofstream(metadata) << json;
  const std::string yaml = fmt::format(
      "payload:\n  id: test\n  state_dir: {}\nlidar:\n  model: {}\n  source: udp\n  address: 127.0.0.1\n"
      "  port: {}\n  calibration: {}\nimu:\n  enabled: true\n  source: ouster\nthreads:\n  lock_memory: false\n",
      (test::binary_dir() / "ouster-imu-live").string(), c.model, lidar_port, metadata.string());
  const std::unique_ptr<Pipeline> pipeline = test::live_pipeline(yaml);
  // Sent once the receiver reads (it drains what came before the session).
  ASSERT_TRUE(test::start_and_wait_for_receiver(*pipeline));
  drivers::UdpSender to_lidar("127.0.0.1", lidar_port);
  drivers::UdpSender to_imu("127.0.0.1", imu_port);
  // At the capture's own pace, as the sensor sends them: the LiDAR clock's
  // estimate (and so the IMU's stamps) follows the host's as it would live.
  drivers::PacedPcapReader reader(dir / c.pcap, 1.0);
  drivers::UdpDatagram d;
  std::size_t imu_sent = 0;
  std::size_t lidar_sent = 0;
  while (reader.next(d)) {
    if (d.dst_port == 7503) imu_sent += to_imu.send(d.payload) ? 1 : 0;
    else lidar_sent += to_lidar.send(d.payload) ? 1 : 0;
  }
  const double sent_s = 1e-9 * static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                                       std::chrono::system_clock::now().time_since_epoch())
                                                       .count());
  const ImuStats& imu = pipeline->stats().imu;  // copied from the source per scan and at the end
  for (int i = 0; i < 200 && pipeline->stats().datagrams.load() < imu_sent + lidar_sent; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  pipeline->end_source();
  pipeline->join();
  std::filesystem::remove(metadata);
  fmt::print("live: {} LiDAR and {} IMU datagrams sent; {} IMU packets read, {} readings, {} before the LiDAR's clock\n",
             lidar_sent, imu_sent, imu.packets.load(), imu.samples.load(), imu.count(ImuProblem::unclocked));
  ASSERT_EQ(imu_sent, c.packets);
  EXPECT_EQ(imu.packets.load(), imu_sent) << "loopback does not lose 30 datagrams";
  EXPECT_EQ(imu.samples.load() + imu.count(ImuProblem::unclocked), imu.packets.load());
  EXPECT_GE(imu.samples.load(), imu_sent - 2);
  EXPECT_EQ(imu.count(ImuProblem::time_back), 0U);
  // Live, stamped on the LiDAR clock mapped to the host's: the last reading
  // within the sending's last 0.1 s (kernel receive times, min-delay filtered).
  EXPECT_NEAR(imu.last_t.load(), sent_s, 0.1);
}

}  // namespace
}  // namespace adit::daemon
