// aditd under a systemd-like supervisor: the test binds a NOTIFY_SOCKET and
// sets WATCHDOG_USEC as systemd does, runs aditd on a real capture, and reads
// the sd_notify(3) datagrams: READY=1 once, WATCHDOG=1 while the workers are
// alive, STATUS= lines, STOPPING=1 at the end. Also checks the unit file.

#include <gtest/gtest.h>

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>
#include <sstream>

#include <fmt/format.h>

#include "daemon_process.hpp"
#include "run_program.hpp"
#include "shared_data.hpp"

namespace adit::test {
namespace {

TEST(Systemd, AditdNotifiesReadyWatchdogStatusAndStopping) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-hdl32e");
  const std::string socket_path = (binary_dir() / fmt::format("notify-{}.sock", getpid())).string();
  ::unlink(socket_path.c_str());
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_NONBLOCK, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof(address.sun_path), "%s", socket_path.c_str());
  ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)), 0);

  const std::string config = (binary_dir() / "systemd-test.yaml").string();
  std::ofstream(config) << fmt::format(
      "payload:\n  id: test\n  state_dir: {}\nlidar:\n  model: HDL-32E\n  source: pcap\n  pcap: {}\n"
      "  calibration: {}\n  replay_speed: 0.25\nthreads:\n  lock_memory: false\n",
      (binary_dir() / "systemd-test-state").string(), (dir / "capture.pcap").string(), (dir / "HDL32.yaml").string());
  // Read as systemd does, while aditd runs: a full datagram queue would block its sd_notify.
  std::vector<std::string> messages;
  std::atomic<bool> done{false};
  std::thread reader([&] {
    std::array<char, 4096> buffer{};
    while (true) {
      const ssize_t n = ::recv(fd, buffer.data(), buffer.size(), 0);
      if (n > 0) {
        messages.emplace_back(buffer.data(), static_cast<std::size_t>(n));
      } else if (done.load()) {
        break;
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    }
  });
  ::setenv("NOTIFY_SOCKET", socket_path.c_str(), 1);
  ::setenv("WATCHDOG_USEC", "400000", 1);  // aditd checks and pets every 200 ms
  const ProgramResult r = run_program({(binary_dir() / "bin/aditd").string(), "--config", config, "--once"});
  ::unsetenv("NOTIFY_SOCKET");
  ::unsetenv("WATCHDOG_USEC");
  done = true;
  reader.join();
  ::close(fd);
  ASSERT_EQ(r.exit_status, 0) << r.err;
  ASSERT_FALSE(messages.empty());
  ::unlink(socket_path.c_str());

  const auto count = [&](const std::string& prefix) {
    return std::count_if(messages.begin(), messages.end(), [&](const std::string& m) { return m.rfind(prefix, 0) == 0; });
  };
  EXPECT_EQ(count("READY=1"), 1);
  EXPECT_GE(count("WATCHDOG=1"), 5);  // the 0.5 s capture replayed at 0.25x: about 2 s, a pet every 0.2 s
  EXPECT_GE(count("STATUS=MAPPING"), 3);  // 2 Hz while the session runs
  EXPECT_EQ(count("STOPPING=1"), 1);
  EXPECT_EQ(messages.back(), "STOPPING=1");
}

TEST(Systemd, UnitIsTypeNotifyWithWatchdogRestartLimitsAndStateDirectory) {
  std::ifstream unit(source_dir() / "systemd/aditd.service");
  ASSERT_TRUE(unit.good());
  std::stringstream text;
  text << unit.rdbuf();
  for (const char* line : {"Type=notify", "WatchdogSec=", "Restart=on-failure", "LimitRTPRIO=", "LimitMEMLOCK=infinity",
                           "StateDirectory=aditd", "--check-config"})
    EXPECT_NE(text.str().find(line), std::string::npos) << line;
  // These two would break real time and GPIO (see FIELD-NOTES): they must not be set.
  EXPECT_EQ(text.str().find("\nRestrictRealtime=yes"), std::string::npos);
  EXPECT_EQ(text.str().find("\nPrivateDevices=yes"), std::string::npos);
  for (const char* line : {"\nUser=adit", "\nCapabilityBoundingSet=\n", "\nNoNewPrivileges=yes", "\nProtectSystem=strict",
                           "\nPrivateTmp=yes", "\nDeviceAllow=char-gpiochip rw"})
    EXPECT_NE(text.str().find(line), std::string::npos) << line;
}

// systemd's own judgement of the unit's sandbox (issue 21: exposure <= 3.0;
// it was 5.7 before the hardening).
TEST(Systemd, SecurityExposureIsAtMostThree) {
  if (std::system("command -v systemd-analyze >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "systemd-analyze is not installed: the exposure is not measured";
  const std::string command =
      "systemd-analyze security --offline=true --no-pager " + (source_dir() / "systemd/aditd.service").string() + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string out;
  std::array<char, 4096> buffer{};
  while (const std::size_t n = std::fread(buffer.data(), 1, buffer.size(), pipe)) out.append(buffer.data(), n);
  ::pclose(pipe);
  const std::string marker = "Overall exposure level for aditd.service: ";
  const std::size_t at = out.find(marker);
  ASSERT_NE(at, std::string::npos) << out;
  const double exposure = std::stod(out.substr(at + marker.size()));
  std::printf("systemd-analyze security --offline=true systemd/aditd.service: exposure %.1f\n", exposure);
  EXPECT_LE(exposure, 3.0) << out;
}

// LoadCredential=command-key:… hands aditd its key in $CREDENTIALS_DIRECTORY;
// lcm.key_file names it so. Without the variable, aditd refuses to start.
TEST(Systemd, AditdReadsTheCommandKeyFromASystemdCredential) {
  const std::filesystem::path work = binary_dir() / fmt::format("credential-{}", getpid());
  std::filesystem::remove_all(work);
  std::filesystem::create_directories(work / "credentials");
  const ProgramResult keygen =
      run_program({(binary_dir() / "bin/adit").string(), "keygen", "--out", (work / "credentials/command-key").string()});
  ASSERT_EQ(keygen.exit_status, 0) << keygen.err;
  std::filesystem::permissions(work / "credentials/command-key", std::filesystem::perms::owner_read);  // as systemd hands it
  const std::string config = (work / "aditd.yaml").string();
  std::ofstream(config) << fmt::format(
      "payload:\n  id: cred{}\n  state_dir: {}\nlidar:\n  model: Mid-360\n  source: udp\n  address: 127.0.0.1\n"
      "  port: {}\nlcm:\n  url: udpm://239.255.76.67:{}?ttl=0\n  key_file: $CREDENTIALS_DIRECTORY/command-key\n"
      "threads:\n  lock_memory: false\n",
      getpid(), (work / "state").string(), 30000 + getpid() % 20000, 20000 + (getpid() + 13) % 30000);

  ::unsetenv("CREDENTIALS_DIRECTORY");
  const ProgramResult refused = run_program({(binary_dir() / "bin/aditd").string(), "--config", config});
  EXPECT_EQ(refused.exit_status, 2);
  EXPECT_NE(refused.err.find("CREDENTIALS_DIRECTORY is not set"), std::string::npos) << refused.err;

  ::setenv("CREDENTIALS_DIRECTORY", (work / "credentials").c_str(), 1);
  std::string log;
  {
    Daemon aditd({(binary_dir() / "bin/aditd").string(), "--config", config}, work / "aditd.log");
    ::unsetenv("CREDENTIALS_DIRECTORY");
    for (int i = 0; i < 100 && log.find("LCM: ") == std::string::npos; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      std::ifstream in(work / "aditd.log");
      log.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    EXPECT_EQ(aditd.stop(), 0);
  }
  EXPECT_NE(log.find(fmt::format("signed commands only, 1 key(s) from {}", (work / "credentials/command-key").string())),
            std::string::npos)
      << log;
  std::filesystem::remove_all(work);
}

}  // namespace
}  // namespace adit::test
