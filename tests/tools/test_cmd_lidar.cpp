// adit pcap-info / decode / pcap-send, run as a user would, on the real captures.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <unistd.h>

#include <array>
#include <cstdio>
#include <string>

#include "../drivers/lidar_packet_builders.hpp"
#include "adit/drivers/lidar/hesai_encoder.hpp"
#include "adit/drivers/lidar/livox_encoder.hpp"
#include "adit/drivers/lidar/scan_files.hpp"
#include "adit/drivers/pcap_writer.hpp"
#include "adit/drivers/udp.hpp"
#include "run_program.hpp"
#include "shared_data.hpp"

namespace {

using adit::test::CommandRun;
CommandRun adit(const std::string& arguments) { return adit::test::run_adit(arguments); }

TEST(CmdLidar, PcapInfoDescribesTheCapture) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-vlp16-dual");
  const CommandRun run = adit("pcap-info " + (dir / "capture.pcap").string() + " --calibration " + (dir / "VLP16.yaml").string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("sensor: velodyne VLP-16 (data on port 2368)"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("port 2368: 603 datagrams"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("packets: 603 ok, 0 auxiliary, 0 foreign, 0 truncated, 0 malformed"), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("scans: 5 (3 complete); packets missing 0"), std::string::npos) << run.output;
}

TEST(CmdLidar, DecodeWritesOneFilePerScanAndRefusesMissingCalibration) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-hdl32e");
  const auto out = std::filesystem::temp_directory_path() / ("adit-decode-" + std::to_string(getpid()));
  std::filesystem::remove_all(out);
  const CommandRun run = adit("decode " + (dir / "capture.pcap").string() + " --calibration " + (dir / "HDL32.yaml").string() +
                       " --out " + out.string() + " --format pcd");
  ASSERT_EQ(run.status, 0) << run.output;
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(out)) files += entry.path().extension() == ".pcd";
  EXPECT_EQ(files, 7u);
  std::vector<adit::drivers::CloudPoint> cloud;
  adit::drivers::read_pcd(out / "scan_000001.pcd", cloud);
  EXPECT_GT(cloud.size(), 30'000u);
  std::filesystem::remove_all(out);

  const CommandRun refused = adit("decode " + (dir / "capture.pcap").string() + " --out " + out.string());
  EXPECT_EQ(refused.status, 2);
  EXPECT_NE(refused.output.find("calibration"), std::string::npos) << refused.output;
  EXPECT_FALSE(std::filesystem::exists(out / "scan_000000.pcd"));
}

TEST(CmdLidar, PcapSendDeliversEveryDatagramOverLoopback) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-vlp16-strongest");
  adit::drivers::UdpReceiverConfig config;
  config.bind_address = "127.0.0.1";
  adit::drivers::UdpReceiver receiver(config);
  const CommandRun run = adit("pcap-send " + (dir / "capture.pcap").string() + " --to 127.0.0.1:" +
                       std::to_string(receiver.port()) + " --speed 10");
  ASSERT_EQ(run.status, 0) << run.output;
  std::size_t received = 0;
  for (auto batch = receiver.receive(200); !batch.empty(); batch = receiver.receive(200)) received += batch.size();
  EXPECT_EQ(received, 84u);
  EXPECT_EQ(receiver.stats().kernel_drops, 0u);
  EXPECT_EQ(adit("pcap-send " + (dir / "capture.pcap").string() + " --to nowhere").status, 2);
}

// The issue-24 symptom: a PandarQT128's 1127-byte packets were "none recognised" and all foreign.
// Synthetic packets of the protocol-3.2 layout (tests/drivers/lidar_packet_builders.hpp); a Mid-360
// capture from the encoder; and packets nobody knows, for the message that names what was seen.
TEST(CmdLidar, DetectsQt128AndMid360AndNamesWhatItDoesNotKnow) {
  const auto dir = std::filesystem::temp_directory_path() / ("adit-detect-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  adit::drivers::UdpEndpoints to2368;
  to2368.src_port = to2368.dst_port = 2368;
  {
    adit::drivers::PcapWriter pcap(dir / "qt128.pcap");
    adit::test::HesaiLayout qt128;
    for (const auto& l : adit::test::hesai_layouts()) {
      if (l.model == "PandarQT128") qt128 = l;
    }
    adit::test::HesaiContent content;
    for (int k = 0; k < 300; ++k) {
      content.first_azimuth = static_cast<std::uint16_t>((k * 40) % 36000);
      content.micros = static_cast<std::uint32_t>(k * 111);
      content.sequence = static_cast<std::uint32_t>(k);
      const auto packet = adit::test::hesai_packet(qt128, content);
      ASSERT_EQ(packet.size(), 1127u);
      pcap.write_udp(1'700'000'000'000'000'000 + k * 111'000LL, to2368, packet);
    }
  }
  adit::drivers::HesaiAngleCorrection angles;
  for (int c = 0; c < 128; ++c) {
    angles.elevation_deg.push_back(52.0F - 0.8F * static_cast<float>(c));
    angles.azimuth_deg.push_back(0.0F);
  }
  {
    std::FILE* f = std::fopen((dir / "qt128.csv").c_str(), "w");
    ASSERT_NE(f, nullptr);
    const std::string csv = adit::drivers::format_hesai_angle_csv(angles);
    std::fwrite(csv.data(), 1, csv.size(), f);
    std::fclose(f);
  }
  CommandRun run = adit("pcap-info " + (dir / "qt128.pcap").string() + " --calibration " + (dir / "qt128.csv").string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("sensor: hesai PandarQT128 (data on port 2368)"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("packets: 300 ok, 0 auxiliary, 0 foreign"), std::string::npos) << run.output;
  run = adit("decode " + (dir / "qt128.pcap").string() + " --family hesai --model PandarQT128 --calibration " +
             (dir / "qt128.csv").string() + " --out " + (dir / "scans").string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("packets: 300 ok"), std::string::npos) << run.output;

  {
    adit::drivers::PcapWriter pcap(dir / "mid360.pcap");
    adit::drivers::UdpEndpoints to56301;
    to56301.src_port = 56300;
    to56301.dst_port = adit::drivers::kLivoxMid360PointPort;
    std::vector<adit::drivers::LivoxRawPoint> points(96, adit::drivers::LivoxRawPoint{3000, 500, 100, 20, 0});
    std::vector<std::uint8_t> bytes(adit::drivers::livox_sdk2_point_packet_bytes(points.size()));
    for (int k = 0; k < 500; ++k) {
      adit::drivers::LivoxSdk2PointPacket p;
      p.time_ns = 1'700'000'000'000'000'000 + k * 480'000LL;
      p.time_interval = 4800;
      p.udp_cnt = static_cast<std::uint16_t>(k);
      p.points = points;
      adit::drivers::encode_livox_sdk2_points(p, bytes);
      pcap.write_udp(p.time_ns + 500'000, to56301, bytes);
    }
  }
  run = adit("pcap-info " + (dir / "mid360.pcap").string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("sensor: livox Mid-360 (data on port 56301)"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("packets: 500 ok"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("scans: 3 (1 complete)"), std::string::npos) << run.output;  // 240 ms from a window start

  {
    adit::drivers::PcapWriter pcap(dir / "unknown.pcap");
    const std::vector<std::uint8_t> junk(777, 0x42);
    for (int k = 0; k < 5; ++k) pcap.write_udp(1'000'000'000 + k * 1000, to2368, junk);
  }
  run = adit("pcap-info " + (dir / "unknown.pcap").string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("sensor: none recognised; saw port 2368 (777 B)"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("known data packets: Velodyne 1206 B"), std::string::npos) << run.output;
  std::filesystem::remove_all(dir);
}

}  // namespace
