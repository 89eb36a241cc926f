// End-to-end: the `adit eval` binary's exit statuses, JSON and plots.

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_adit.hpp"
#include "temp_file.hpp"

namespace adit {
namespace {

using test::adit_eval;
using test::EvalRun;
using test::q;
using test::TempFile;
using namespace std::string_literals;

// A TUM trajectory: an L-shaped drive, 10 Hz, one pose per 0.1 m; positions
// are scaled by `scale`, then `shift_x` is added; `t0` is added to every stamp.
std::string tum_lines(double t0, double shift_x, double scale = 1.0) {
  std::ostringstream out;
  for (int i = 0; i < 60; ++i) {
    const double x = i < 30 ? 0.1 * i : 3.0, y = i < 30 ? 0.0 : 0.1 * (i - 30);
    out << t0 + 0.1 * i << ' ' << scale * x + shift_x << ' ' << scale * y << " 0 0 0 0 1\n";
  }
  return out.str();
}

TEST(AditEval, TrajJsonGivesApeOfAKnownOffset) {
  const TempFile ref(tum_lines(100.0, 0.0)), est(tum_lines(100.0, 0.5));
  const EvalRun run = adit_eval("traj --ref "s + q(ref) + " --est " + q(est) + " --align none --json");
  ASSERT_EQ(run.status, 0) << run.output;
  const auto j = nlohmann::json::parse(run.output);
  EXPECT_EQ(j["associated_pairs"].get<int>(), 60);
  EXPECT_NEAR(j["ape"]["translation_m"]["rmse"].get<double>(), 0.5, 1e-9);
  EXPECT_NEAR(j["rpe"]["translation_m"]["max"].get<double>(), 0.0, 1e-9);
  // SE(3) alignment removes the offset.
  const EvalRun aligned = adit_eval("traj --ref "s + q(ref) + " --est " + q(est) + " --json");
  ASSERT_EQ(aligned.status, 0) << aligned.output;
  EXPECT_NEAR(nlohmann::json::parse(aligned.output)["ape"]["translation_m"]["rmse"].get<double>(), 0.0, 1e-6);
}

TEST(AditEval, RpePairsChosenAlongEstimateOrReference) {
  // The estimate is 10 % too long. 1.05 m of path is 11 reference steps
  // (1.1 m, error 0.11 m) but 10 estimate steps (1.0 m of reference, 0.1 m).
  const TempFile ref(tum_lines(0.0, 0.0)), est(tum_lines(0.0, 0.0, 1.1));
  const std::string common =
      "traj --ref "s + q(ref) + " --est " + q(est) + " --align none --delta 1.05 --delta-unit m --json";
  const EvalRun along_est = adit_eval(common);
  const EvalRun along_ref = adit_eval(common + " --pairs-on ref");
  ASSERT_EQ(along_est.status, 0) << along_est.output;
  ASSERT_EQ(along_ref.status, 0) << along_ref.output;
  EXPECT_NEAR(nlohmann::json::parse(along_est.output)["rpe"]["translation_m"]["max"].get<double>(), 0.10, 1e-9);
  EXPECT_NEAR(nlohmann::json::parse(along_ref.output)["rpe"]["translation_m"]["max"].get<double>(), 0.11, 1e-9);
}

TEST(AditEval, TrajWritesReadableSvgPlots) {
  const TempFile ref(tum_lines(0.0, 0.0)), est(tum_lines(0.0, 0.2));
  const std::string prefix = ref.path().string() + "-plot";
  const EvalRun run = adit_eval("traj --ref "s + q(ref) + " --est " + q(est) + " --svg '" + prefix + "'");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("APE translation (m)"), std::string::npos) << run.output;
  for (const char* suffix : {"-plan.svg", "-ape.svg"}) {
    std::ifstream in(prefix + suffix);
    const std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(svg.rfind("<svg ", 0), 0u) << suffix;
    EXPECT_NE(svg.find("<polyline"), std::string::npos) << suffix;
    EXPECT_NE(svg.find("</svg>"), std::string::npos) << suffix;
    std::filesystem::remove(prefix + suffix);
  }
}

TEST(AditEval, MalformedLineExits2NamingFileAndLine) {
  const TempFile ref(tum_lines(0.0, 0.0)), est("0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 1\n0.2 0 zero 0 0 0 0 1\n");
  const EvalRun run = adit_eval("traj --ref "s + q(ref) + " --est " + q(est));
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find(est.path().string() + ":3"), std::string::npos) << run.output;
}

TEST(AditEval, TimeGoingBackwardsExits2) {
  const TempFile ref(tum_lines(0.0, 0.0)), est("0.5 0 0 0 0 0 0 1\n0.4 0 0 0 0 0 0 1\n");
  const EvalRun run = adit_eval("traj --ref "s + q(ref) + " --est " + q(est));
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("backwards"), std::string::npos) << run.output;
}

TEST(AditEval, NoAssociatedPairsExits2) {
  const TempFile ref(tum_lines(0.0, 0.0)), est(tum_lines(1000.0, 0.0));
  const EvalRun run = adit_eval("traj --ref "s + q(ref) + " --est " + q(est));
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("associate"), std::string::npos) << run.output;
}

TEST(AditEval, MissingFileAndUnknownOptionExit2) {
  EXPECT_EQ(adit_eval("traj --ref /nonexistent/ref.txt --est /nonexistent/est.txt").status, 2);
  EXPECT_EQ(adit_eval("traj --bogus").status, 2);
}

TEST(AditEval, EndpointJsonHandComputed) {
  const TempFile est("0 0 0 0 0 0 0 1\n1 3 0 0 0 0 0 1\n2 3 4 0 0 0 0 1\n3 0 4 0 0 0 0 1\n");
  const EvalRun run = adit_eval("endpoint --est "s + q(est) + " --true-delta 0,4.3,0 --json");
  ASSERT_EQ(run.status, 0) << run.output;
  const auto j = nlohmann::json::parse(run.output);
  EXPECT_NEAR(j["drift_m"].get<double>(), 0.3, 1e-9);
  EXPECT_NEAR(j["length_m"].get<double>(), 10.0, 1e-9);
  EXPECT_NEAR(j["drift_rate"].get<double>(), 0.03, 1e-9);
  EXPECT_EQ(adit_eval("endpoint --est "s + q(est) + " --true-delta 1,2").status, 2);
}

constexpr const char* kTruth = "id,x,y,z\nA,0,0,0\nB,10,0,0\nC,0,10,0\nD,10,10,1\n";

TEST(AditEval, TargetsJsonAndPlot) {
  const TempFile truth(kTruth, ".csv");
  const TempFile map("id,x,y,z\nA,0,0,0\nB,10,0,0\nC,0,10,0\nD,10,10,1.05\n", ".csv");
  const std::string svg = truth.path().string() + ".svg";
  const EvalRun run =
      adit_eval("targets --truth "s + q(truth) + " --map " + q(map) + " --control A,B,C --json --svg '" + svg + "'");
  ASSERT_EQ(run.status, 0) << run.output;
  const auto j = nlohmann::json::parse(run.output);
  EXPECT_NEAR(j["absolute"]["points"][3]["dz"].get<double>(), -0.05, 1e-9);
  EXPECT_TRUE(j["leave_one_out"][0]["distance"].is_null());
  EXPECT_TRUE(std::filesystem::exists(svg));
  std::filesystem::remove(svg);
}

TEST(AditEval, TooFewOrCollinearControlTargetsExit2) {
  const TempFile truth(kTruth, ".csv");
  const EvalRun few = adit_eval("targets --truth "s + q(truth) + " --map " + q(truth) + " --control A,B");
  EXPECT_EQ(few.status, 2) << few.output;
  EXPECT_NE(few.output.find("at least 3"), std::string::npos) << few.output;
  const TempFile line("id,x,y,z\nP,0,0,0\nQ,5,1,0\nR,10,2,0\n", ".csv");
  const EvalRun collinear = adit_eval("targets --truth "s + q(line) + " --map " + q(line));
  EXPECT_EQ(collinear.status, 2) << collinear.output;
  EXPECT_NE(collinear.output.find("one line"), std::string::npos) << collinear.output;
  const TempFile bad("id,x,y,z\nA,0,0\n", ".csv");
  const EvalRun malformed = adit_eval("targets --truth "s + q(truth) + " --map " + q(bad));
  EXPECT_EQ(malformed.status, 2) << malformed.output;
  EXPECT_NE(malformed.output.find(bad.path().string() + ":2"), std::string::npos) << malformed.output;
}

}  // namespace
}  // namespace adit
