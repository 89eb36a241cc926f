// adit bench loops on a short simulated drive (no timing asserted: the bench
// reports times, the test checks it measured what it says): every keyframe's
// search timed, the graph solved, the odometry's baseline present; a folder
// that is not a session exits with status 2 naming the file.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "run_program.hpp"
#include "shared_data.hpp"
#include "sim_sessions.hpp"
#include "temp_file.hpp"

namespace {

using adit::test::CommandRun;
CommandRun adit(const std::string& arguments) { return adit::test::run_adit(arguments); }

TEST(CmdBenchLoops, TimesEveryKeyframeAndTheGraph) {
  const CommandRun run =
      adit("bench loops --session " + adit::test::mine_drive_12s().string() +
           " --graph-keyframes 600 --graph-runs 1 --optimize-every-s 2.5 --json");
  ASSERT_EQ(run.status, 0) << run.output;
  const auto j = nlohmann::json::parse(run.output.substr(run.output.find('{')));
  const int keyframes = j["keyframes"].get<int>();
  EXPECT_GE(keyframes, 8) << run.output;  // a 12 s drive, a keyframe a metre
  EXPECT_EQ(j["search"]["count"].get<int>(), keyframes);
  EXPECT_EQ(j["verification"]["count"].get<int>(), j["candidates"].get<int>());
  EXPECT_GT(j["odometry_ms_per_scan"]["median"].get<double>(), 0.0);
  EXPECT_GT(j["search"]["median_vs_odometry"].get<double>(), 0.0);
  EXPECT_EQ(j["graph"]["keyframes"].get<int>(), 600);
  EXPECT_EQ(j["graph"]["loops"].get<int>(), 10);  // every 10 keyframes from 500 on
  EXPECT_TRUE(j["graph"]["converged"].get<bool>()) << run.output;
  EXPECT_EQ(j["graph"]["wall"]["count"].get<int>(), 1);
  EXPECT_EQ(j["optimize_every_s"].get<double>(), 2.5);
  EXPECT_GE(j["optimisation_in_session_iterations"]["total"].get<int>(), j["optimisation_in_session"]["count"].get<int>());
}

TEST(CmdBenchLoops, AFolderWithoutASessionExitsWithStatus2) {
  const adit::test::TempFolder empty;
  const CommandRun run = adit("bench loops --session " + empty.path().string());
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("session.yaml"), std::string::npos) << run.output;
}

}  // namespace
