// adit bench prior-map on a short simulated building drive (no timing
// asserted): the starts are counted, and the odometry run twice, without the
// prior and anchored to it, scored against the truth with its figures under
// the keys the issue names.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "run_program.hpp"
#include "shared_data.hpp"
#include "temp_file.hpp"

namespace {

using adit::test::CommandRun;
CommandRun adit(const std::string& arguments) { return adit::test::run_adit(arguments); }

std::filesystem::path simulated_building() {
  const auto dir = adit::test::binary_dir() / "test-sessions" / "bench-prior-map";
  if (!std::filesystem::exists(dir / "lidar.pcap")) {
    const CommandRun sim = adit("sim --scene building --platform robot --duration 15 --seed 2 --out " + dir.string());
    EXPECT_EQ(sim.status, 0) << sim.output;
  }
  return dir;
}

TEST(CmdBenchPriorMap, LocalisesAndRunsTheOdometryAnchoredToThePrior) {
  const CommandRun run = adit("bench prior-map --session " + simulated_building().string() + " --starts 3 --json");
  ASSERT_EQ(run.status, 0) << run.output;
  const auto j = nlohmann::json::parse(run.output.substr(run.output.find('{')));
  EXPECT_EQ(j["starts"].get<int>(), 3);
  EXPECT_EQ(j["false_localisations"].get<int>(), 0) << run.output;
  const auto& with = j["with_prior"];
  const auto& without = j["without_prior"];
  ASSERT_TRUE(with["anchored"].get<bool>()) << run.output;
  EXPECT_LT(with["anchored_at_s"].get<double>(), 5.0);
  ASSERT_TRUE(j["drift_percent_with_prior"].is_number()) << run.output;
  ASSERT_TRUE(j["drift_percent_without_prior"].is_number()) << run.output;
  EXPECT_FALSE(without["anchored"].get<bool>());
  // Both runs scored over the same drive.
  EXPECT_GT(with["path_m"].get<double>(), 5.0);
  EXPECT_DOUBLE_EQ(with["path_m"].get<double>(), without["path_m"].get<double>());
  EXPECT_EQ(with["invalid_poses"].get<int>(), 0);
  // Placed by its own localisation, the anchored run stays within a few cm of the truth everywhere.
  EXPECT_LT(with["ape_max_m"].get<double>(), 0.05) << run.output;
}

TEST(CmdBenchPriorMap, NoDriftSkipsTheOdometryAndSaysSo) {
  const CommandRun run = adit("bench prior-map --session " + simulated_building().string() + " --starts 1 --no-drift");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("drift_percent_with_prior not measured (--no-drift)"), std::string::npos) << run.output;
}

TEST(CmdBenchPriorMap, AFolderWithoutASessionExitsWithStatus2) {
  const adit::test::TempFolder empty;
  const CommandRun run = adit("bench prior-map --session " + empty.path().string());
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("session.yaml"), std::string::npos) << run.output;
}

}  // namespace
