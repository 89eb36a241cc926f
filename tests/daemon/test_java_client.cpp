// The Java bindings and tablet client (protocol/java, build/java/adit-lcm.jar)
// against a running aditd with a command key, over real LCM multicast on
// loopback: status, watch, an unsigned START refused, signed START and STOP
// executed; and the watch placing the last pose in the map frame by the
// session's frame_t. Skips with a message when the jar was not built (no
// javac or liblcm-java).

#include <gtest/gtest.h>

#include <lcm/lcm-cpp.hpp>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

#include <fmt/format.h>

#include "adit/frame_t.hpp"
#include "adit/pose_t.hpp"
#include "adit/protocol/channels.hpp"
#include "adit/status_t.hpp"
#include "daemon_process.hpp"
#include "run_program.hpp"
#include "shared_data.hpp"

namespace adit::test {
namespace {

using namespace std::chrono_literals;

struct Java {
  std::string url;
  std::string payload;
  ProgramResult run(const std::vector<std::string>& args) const {
    std::vector<std::string> argv{ADIT_JAVA_EXECUTABLE, "-cp", std::string(ADIT_JAVA_JAR) + ":" + ADIT_LCM_JAR,
                                  "adit.tablet.AditTool"};
    argv.insert(argv.end(), args.begin(), args.end());
    for (const std::string& a : {std::string("--payload"), payload, std::string("--lcm-url"), url})
      argv.push_back(a);
    return run_program(argv);
  }
};

bool java_built() { return !std::string(ADIT_JAVA_JAR).empty() && std::filesystem::exists(ADIT_JAVA_JAR); }
constexpr const char* kNoJava = "the Java bindings were not built (needs javac 17 and liblcm-java: scripts/install-deps.sh)";

TEST(JavaClient, StatusWatchAndSignedStartStopAgainstAditd) {
  if (!java_built()) GTEST_SKIP() << kNoJava;
  const std::filesystem::path work = binary_dir() / fmt::format("java-client-{}", ::getpid());
  std::filesystem::remove_all(work);
  std::filesystem::create_directories(work);
  const Java java{fmt::format("udpm://239.255.76.67:{}?ttl=0", 20000 + (::getpid() + 11) % 30000),
                  fmt::format("java{}", ::getpid())};
  const std::string key = (work / "command.key").string();
  const ProgramResult keygen = run_program({(binary_dir() / "bin/adit").string(), "keygen", "--out", key});
  ASSERT_EQ(keygen.exit_status, 0) << keygen.err;

  // A payload on a LiDAR port nobody sends to: it starts and stops sessions
  // that see no packets, which is all the commands need.
  const std::filesystem::path config = work / "aditd.yaml";
  std::ofstream(config) << fmt::format(
      "payload:\n  id: {}\n  state_dir: {}\nlidar:\n  model: Mid-360\n  source: udp\n  address: 127.0.0.1\n"
      "  port: {}\nlcm:\n  url: {}\n  key_file: {}\nthreads:\n  lock_memory: false\n",
      java.payload, (work / "state").string(), 30000 + ::getpid() % 20000, java.url, key);
  Daemon aditd({(binary_dir() / "bin/aditd").string(), "--config", config.string()}, work / "aditd.log");

  ProgramResult r;
  for (int attempt = 0; attempt < 10; ++attempt) {  // aditd takes a moment to start
    r = java.run({"status", "--timeout", "2"});
    if (r.exit_status == 0) break;
  }
  ASSERT_EQ(r.exit_status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find(fmt::format("payload {} state IDLE", java.payload)), std::string::npos) << r.out;

  r = java.run({"start"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("START rejected: unsigned: this payload accepts only signed commands"), std::string::npos)
      << r.err;

  r = java.run({"start", "--key", key});
  ASSERT_EQ(r.exit_status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("(state MAPPING, session "), std::string::npos) << r.out;

  r = java.run({"watch", "--duration", "1.5"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("status MAPPING"), std::string::npos) << r.out;

  r = java.run({"stop", "--key", key});
  ASSERT_EQ(r.exit_status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("state STOPPING"), std::string::npos) << r.out;
  for (int attempt = 0; attempt < 20; ++attempt) {
    r = java.run({"ping", "--key", key});
    if (r.out.find("state IDLE") != std::string::npos) break;
    std::this_thread::sleep_for(250ms);
  }
  EXPECT_NE(r.out.find("PING: pong (state IDLE"), std::string::npos) << r.out << r.err;

  // A key file others may read is refused by the Java client too.
  std::filesystem::permissions(key, std::filesystem::perms::group_read, std::filesystem::perm_options::add);
  r = java.run({"ping", "--key", key});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("chmod 600"), std::string::npos) << r.err;
  EXPECT_EQ(aditd.stop(), 0);
  std::ifstream log(work / "aditd.log");
  const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("commands: signed commands only, 1 key(s)"), std::string::npos) << text;
}

// A payload anchored to a prior map a quarter turn and 100 m away, played by
// the test itself over LCM (poses of session "20261129T000000Z", the frame of
// `frame_session`) while `AditTool watch` runs: its output.
ProgramResult watch_an_anchored_payload(const std::string& frame_session) {
  const Java java{fmt::format("udpm://239.255.76.67:{}?ttl=0", 20000 + (::getpid() + 13) % 30000),
                  fmt::format("javaframe{}", ::getpid())};
  lcm::LCM lcm(java.url);
  if (!lcm.good()) return {.exit_status = -1, .out = "", .err = "LCM did not start"};
  std::atomic<bool> running{true};
  std::thread payload([&] {
    status_t s{};
    s.schema = 1;
    s.payload_id = java.payload;
    s.session_id = "20261129T000000Z";
    s.state = 1;  // MAPPING
    pose_t p{};
    p.schema = 1;
    p.session_id = s.session_id;
    p.position[0] = 1.0;
    p.position[1] = 2.0;
    p.position[2] = 3.0;
    p.orientation[0] = 1.0;
    p.flags = pose_t::FLAG_VALID;
    frame_t f{};
    f.schema = 2;
    f.payload_id = java.payload;
    f.session_id = frame_session;
    f.source = frame_t::SOURCE_PRIOR_MAP;
    f.position[0] = 100.0;
    f.orientation[0] = std::sqrt(0.5);  // a quarter turn about z
    f.orientation[3] = std::sqrt(0.5);
    f.tiles_position[0] = 100.0;
    f.tiles_orientation[0] = std::sqrt(0.5);
    f.tiles_orientation[3] = std::sqrt(0.5);
    while (running) {
      lcm.publish(protocol::channel_name(java.payload, protocol::Channel::status), &s);
      lcm.publish(protocol::channel_name(java.payload, protocol::Channel::frame), &f);
      for (int i = 0; i < 5 && running; ++i) {
        ++p.seq;
        lcm.publish(protocol::channel_name(java.payload, protocol::Channel::pose), &p);
        std::this_thread::sleep_for(20ms);
      }
    }
  });
  ProgramResult r = java.run({"watch", "--duration", "1.5"});
  running = false;
  payload.join();
  return r;
}

// The watch prints the last pose in the odometry frame and, through the
// session's frame_t, in the map frame (R·p + t), as the console and `adit
// download` place them.
TEST(JavaClient, WatchPlacesTheLastPoseInTheSessionsMapFrame) {
  if (!java_built()) GTEST_SKIP() << kNoJava;
  const ProgramResult r = watch_an_anchored_payload("20261129T000000Z");
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("frame PRIOR_MAP session 20261129T000000Z"), std::string::npos) << r.out;
  // R_z(90°)·(1, 2, 3) + (100, 0, 0) = (98, 1, 3).
  EXPECT_NE(r.out.find("last pose: odometry (1.000, 2.000, 3.000) m, map (98.000, 1.000, 3.000) m (PRIOR_MAP)"),
            std::string::npos)
      << r.out;
}

// A frame of another session (an earlier one's, still on the channel) does
// not place this session's pose.
TEST(JavaClient, AnotherSessionsFrameDoesNotPlaceThePose) {
  if (!java_built()) GTEST_SKIP() << kNoJava;
  const ProgramResult r = watch_an_anchored_payload("20261128T000000Z");
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("last pose: odometry (1.000, 2.000, 3.000) m, map (1.000, 2.000, 3.000) m (ODOMETRY)"),
            std::string::npos)
      << r.out;
}

}  // namespace
}  // namespace adit::test
