// adit sim run as a user would: a session that adit's own tools read, and
// impossible options refused with exit status 2 and one line naming the option.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#include "run_program.hpp"
#include "shared_data.hpp"

namespace {

using adit::test::CommandRun;
CommandRun adit(const std::string& arguments) { return adit::test::run_adit(arguments); }

TEST(CmdSim, WritesASessionThatTheToolsRead) {
  const auto out = adit::test::binary_dir() / "test-sessions" / "cmd-sim";
  std::filesystem::remove_all(out);
  const CommandRun run = adit("sim --scene drift --platform robot --sensor VLP-16 --duration 12 --seed 4 --out " + out.string());
  ASSERT_EQ(run.status, 0) << run.output;
  const CommandRun check = adit("config check " + (out / "session.yaml").string());
  EXPECT_EQ(check.status, 0) << check.output;
  const CommandRun info = adit("pcap-info " + (out / "lidar.pcap").string() + " --calibration " + (out / "VLP16.yaml").string());
  ASSERT_EQ(info.status, 0) << info.output;
  EXPECT_NE(info.output.find("sensor: velodyne VLP-16 (data on port 2368)"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("0 malformed"), std::string::npos) << info.output;
}

TEST(CmdSim, ImpossibleOptionsExitWithStatus2) {
  const auto out = adit::test::binary_dir() / "test-sessions" / "cmd-sim-bad";
  for (const auto& [options, key] : {std::pair{"--sensor HDL-64E", "--sensor"}, std::pair{"--duration -3", "--duration"},
                                     std::pair{"--platform boat", "--platform"}, std::pair{"--speed 2", "--speed"},
                                     std::pair{"--lateral-offset-m 4", "--lateral-offset-m"},
                                     std::pair{"--mount-rpy-deg 200 0 0", "--mount-rpy-deg"}}) {
    const CommandRun run = adit(std::string("sim ") + options + " --out " + out.string());
    EXPECT_EQ(run.status, 2) << options << ": " << run.output;
    EXPECT_NE(run.output.find(key), std::string::npos) << options << ": " << run.output;
    EXPECT_FALSE(std::filesystem::exists(out / "lidar.pcap")) << options;
  }
}

}  // namespace
