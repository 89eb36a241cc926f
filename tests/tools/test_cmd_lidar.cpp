// adit pcap-info / decode / pcap-send, run as a user would, on the real captures.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <unistd.h>

#include <array>
#include <cstdio>
#include <string>

#include "adit/drivers/lidar/scan_files.hpp"
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

}  // namespace
