// adit bench attitude on a simulated drive: registration against a map placed
// by the truth recovers roll and pitch to a few hundredths of a degree (the
// baseline the odometry's own-map figure is read against), and bad input
// exits with status 2 naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "printed_figure.hpp"
#include "run_program.hpp"
#include "shared_data.hpp"
#include "sim_sessions.hpp"

namespace {

using adit::test::CommandRun;
CommandRun adit(const std::string& arguments) { return adit::test::run_adit(arguments); }

using adit::test::printed_figure;

TEST(CmdBenchAttitude, RegistrationAgainstTheTrueMapRecoversTheTilt) {
  const auto d = adit::test::mine_drive_12s();
  const CommandRun run = adit("bench attitude --pcap " + (d / "lidar.pcap").string() + " --model VLP-16 --calibration " +
                              (d / "VLP16.yaml").string() + " --truth " + (d / "truth_sensor.tum").string());
  ASSERT_EQ(run.status, 0) << run.output;
  const std::string baseline = "  against the true map (baseline):";
  // Measured 0.022 / 0.012 deg rms (roll / pitch) on this drive.
  EXPECT_LT(printed_figure(run.output, baseline, "roll error rms "), 0.06) << run.output;
  EXPECT_LT(printed_figure(run.output, baseline, "pitch rms "), 0.06) << run.output;
  for (const std::string line : {"  against the previous scan alone:", "  against its own map:"}) {
    const double roll = printed_figure(run.output, line, "roll error rms ");
    EXPECT_TRUE(std::isfinite(roll)) << line << "\n" << run.output;
    EXPECT_LT(roll, 1.0) << line << "\n" << run.output;  // a registration gone astray, not a tilt error
  }
  EXPECT_NE(run.output.find("attitude: 118 scans"), std::string::npos) << run.output;
}

TEST(CmdBenchAttitude, AMissingTruthExitsWithStatus2NamingIt) {
  const auto d = adit::test::mine_drive_12s();
  const CommandRun run = adit("bench attitude --pcap " + (d / "lidar.pcap").string() + " --model VLP-16 --calibration " +
                              (d / "VLP16.yaml").string() + " --truth /nonexistent/truth.tum");
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("/nonexistent/truth.tum"), std::string::npos) << run.output;
}

}  // namespace
