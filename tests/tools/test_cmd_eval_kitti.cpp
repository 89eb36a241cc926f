// `adit eval traj` on KITTI 00 through the command line reproduces the
// published reference values.

#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_adit.hpp"

namespace adit::test {
namespace {

TEST(AditEvalRealData, Kitti00CommandLineMatchesReferenceApeAndRpe) {
  ADIT_REQUIRE_SHARED_DATA(dir, "trajectories/kitti-00");
  std::string args = "traj --ref '";
  args += (dir / "KITTI_00_gt.txt").string();
  args += "' --est '";
  args += (dir / "KITTI_00_ORB.txt").string();
  args += "' --delta 10 --delta-unit m --json";
  const EvalRun run = adit_eval(args);
  ASSERT_EQ(run.status, 0) << run.output;
  const auto got = nlohmann::json::parse(run.output);
  std::ifstream in(dir / "reference-metrics.json");
  const auto want = nlohmann::json::parse(in)["results"];
  const auto near = [](double a, double b) { return std::abs(a - b) <= 1e-4 * std::abs(b); };
  for (const char* stat : {"rmse", "mean", "median", "std", "min", "max", "sse"}) {
    EXPECT_PRED2(near, got["ape"]["translation_m"][stat].get<double>(), want[0]["stats"][stat].get<double>()) << stat;
    EXPECT_PRED2(near, got["rpe"]["translation_m"][stat].get<double>(), want[1]["stats"][stat].get<double>()) << stat;
  }
}

}  // namespace
}  // namespace adit::test
