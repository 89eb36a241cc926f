// The host clock stepped by NTP or PTP while mapping: aditd maps a simulated
// drive received live over UDP on loopback while libfaketime steps its wall
// clock 2 s ahead and, 4 s later, back. The kernel's receive stamps and the
// process's own clock readings disagree then, as they do for a moment at a
// real step. The trajectory's stamps must run on without a jump either way (a
// jump ahead would make the odometry predict 2 s of motion; one back would
// drop 2 s of scans), and the status and summary count both steps.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/slam/tum.hpp"
#include "daemon_process.hpp"
#include "run_program.hpp"
#include "sim_sessions.hpp"
#include "shared_data.hpp"

namespace adit::test {
namespace {

using namespace std::chrono_literals;

constexpr const char* kFaketime = "/usr/lib/x86_64-linux-gnu/faketime/libfaketimeMT.so.1";

TEST(ClockSteps, WallClockSteppedAheadAndBackLeavesTheTrajectoryContinuousAndIsCounted) {
  if (!std::filesystem::exists(kFaketime)) GTEST_SKIP() << "libfaketime is absent (scripts/install-deps.sh installs it)";
  const std::filesystem::path session = mine_drive_12s();
  ASSERT_TRUE(std::filesystem::exists(session / "lidar.pcap"));
  const std::filesystem::path work = binary_dir() / fmt::format("clock-steps-{}", ::getpid());
  std::filesystem::remove_all(work);
  std::filesystem::create_directories(work);
  const std::string payload = fmt::format("clock{}", ::getpid());
  const std::string url = fmt::format("udpm://239.255.76.67:{}?ttl=0", 20000 + (::getpid() + 17) % 30000);
  const int port = 30000 + (::getpid() + 5) % 20000;
  std::ofstream(work / "aditd.yaml") << fmt::format(
      "payload:\n  id: {}\n  state_dir: {}\n"
      "lidar:\n  model: VLP-16\n  source: udp\n  address: 127.0.0.1\n  port: {}\n  calibration: {}\n"
      "  extrinsics:\n    xyz_m: [0.2, 0, 0.45]\n    rpy_deg: [0, 0, 0]\n"
      "lcm:\n  url: {}\nsession:\n  autostart: true\n  exports: [ply]\n  record_lidar: false\n"
      "threads:\n  lock_memory: false\n",
      payload, (work / "state").string(), port, (session / "VLP16.yaml").string(), url);
  const std::filesystem::path offset = work / "faketime";
  std::ofstream(offset) << "+0\n";
  Daemon aditd({(binary_dir() / "bin/aditd").string(), "--config", (work / "aditd.yaml").string()}, work / "aditd.log",
               {std::string("LD_PRELOAD=") + kFaketime, "FAKETIME_TIMESTAMP_FILE=" + offset.string(),
                "FAKETIME_CACHE_DURATION=1", "FAKETIME_DONT_FAKE_MONOTONIC=1",
                // A sanitizer build wants its runtime first; libfaketime is preloaded before it.
                "ASAN_OPTIONS=verify_asan_link_order=0:detect_leaks=1:abort_on_error=1"});
  const std::string client = fmt::format("--payload {} --lcm-url '{}' --timeout 5", payload, url);
  ASSERT_EQ(run_adit("ping " + client).status, 0) << "aditd did not answer (aditd.log)";

  std::thread sender([&] {
    run_adit(fmt::format("pcap-send {} --to 127.0.0.1:{} --speed 1", (session / "lidar.pcap").string(), port));
  });
  std::this_thread::sleep_for(4s);
  std::ofstream(offset) << "+2s\n";  // the wall clock jumps 2 s ahead
  std::this_thread::sleep_for(4s);
  std::ofstream(offset) << "+0\n";  // and back
  std::this_thread::sleep_for(2s);
  const CommandRun status = run_adit("status " + client);
  sender.join();
  std::this_thread::sleep_for(500ms);
  ASSERT_EQ(aditd.stop(), 0) << "aditd.log";

  EXPECT_NE(status.output.find("host clock stepped 2 times"), std::string::npos) << status.output;
  std::filesystem::path dir;
  for (const auto& e : std::filesystem::directory_iterator(work / "state" / "sessions")) dir = e.path();
  ASSERT_TRUE(std::filesystem::exists(dir / "summary.json")) << "aditd.log";
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(dir / "summary.json"));
  EXPECT_EQ(summary["host_clock"]["steps"], 2) << summary.dump();
  EXPECT_NEAR(summary["host_clock"]["last_step_s"].get<double>(), -2.0, 0.05);

  // Every pose follows the one before by about a scan period (0.1 s; a scan
  // dropped in between makes 0.2 s), never 2 s more or less.
  const std::vector<double> stamps = slam::read_tum(dir / "trajectory.tum").stamps;
  ASSERT_GT(stamps.size(), 90U) << "12 s at 10 Hz";
  double widest = 0.0;
  double narrowest = 1e9;
  for (std::size_t i = 1; i < stamps.size(); ++i) {
    widest = std::max(widest, stamps[i] - stamps[i - 1]);
    narrowest = std::min(narrowest, stamps[i] - stamps[i - 1]);
  }
  EXPECT_LT(widest, 0.35);
  EXPECT_GT(narrowest, 0.0);
  EXPECT_NEAR(stamps.back() - stamps.front(), 11.8, 0.6) << "the drive's span, not 2 s more or less";
  std::filesystem::remove_all(work);
}

}  // namespace
}  // namespace adit::test
