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
  // Trying again as aditd does can only add starts found, never lose one.
  EXPECT_DOUBLE_EQ(j["retry_s"].get<double>(), 10.0);
  EXPECT_GE(j["localisation_success_rate_retrying"].get<double>(), j["localisation_success_rate"].get<double>());
  EXPECT_EQ(j["false_localisations_retrying"].get<int>(), 0) << run.output;
  if (j["localisation_success_rate_retrying"].get<double>() > 0.0) {
    // At least the second of scans and the search itself.
    EXPECT_GT(j["median_time_to_localise_s"].get<double>(), 0.9);
    EXPECT_LE(j["median_time_to_localise_s"].get<double>(), j["max_time_to_localise_s"].get<double>());
  }
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

// One try (--retry-s 0): taken at once (--no-confirm), the rates agree; a
// found pose waiting for a second try to agree is never taken.
TEST(CmdBenchPriorMap, RetryZeroTriesOnceSoOnlyAnUnconfirmedTryIsTaken) {
  const std::string args = "bench prior-map --session " + simulated_building().string() + " --starts 2 --no-drift --retry-s 0 --json";
  const CommandRun once = adit(args + " --no-confirm");
  ASSERT_EQ(once.status, 0) << once.output;
  const auto j = nlohmann::json::parse(once.output.substr(once.output.find('{')));
  EXPECT_DOUBLE_EQ(j["localisation_success_rate_retrying"].get<double>(), j["localisation_success_rate"].get<double>());
  EXPECT_EQ(j["false_localisations_retrying"].get<int>(), j["false_localisations"].get<int>());
  const CommandRun confirmed = adit(args);
  ASSERT_EQ(confirmed.status, 0) << confirmed.output;
  const auto k = nlohmann::json::parse(confirmed.output.substr(confirmed.output.find('{')));
  EXPECT_GT(k["localisation_success_rate"].get<double>(), 0.0) << confirmed.output;
  EXPECT_DOUBLE_EQ(k["localisation_success_rate_retrying"].get<double>(), 0.0);
}

// A crew's hint, given once at the start, narrows every try (aditd keeps it):
// later tries can still find the pose, never a wrong one here.
TEST(CmdBenchPriorMap, AHintGivenOnceNarrowsEveryTry) {
  const CommandRun run =
      adit("bench prior-map --session " + simulated_building().string() + " --starts 2 --no-drift --hint-m 3 --json");
  ASSERT_EQ(run.status, 0) << run.output;
  const auto j = nlohmann::json::parse(run.output.substr(run.output.find('{')));
  EXPECT_EQ(j["false_localisations_retrying"].get<int>(), 0) << run.output;
  EXPECT_GT(j["localisation_success_rate_retrying"].get<double>(), 0.0) << run.output;
}

TEST(CmdBenchPriorMap, AFolderWithoutASessionExitsWithStatus2) {
  const adit::test::TempFolder empty;
  const CommandRun run = adit("bench prior-map --session " + empty.path().string());
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("session.yaml"), std::string::npos) << run.output;
}

}  // namespace
