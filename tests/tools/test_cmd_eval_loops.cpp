// End-to-end: `adit eval loops` on a hand-made session folder (summary.json
// with the graph's loops, keyframes.tum) and truth: its figures, exit statuses
// and errors naming the file.

#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_adit.hpp"
#include "temp_file.hpp"

namespace adit {
namespace {

using test::adit_eval;
using test::EvalRun;
using test::TempFolder;
using namespace std::string_literals;

// A straight line out along x and back at 1 m/s: 40 m out, 40 m back; the
// truth at 10 Hz, keyframes once a second (the way back faces -x).
void write_truth(const std::filesystem::path& file, double seconds) {
  std::ofstream out(file);
  for (int i = 0; i <= static_cast<int>(10 * seconds); ++i) {
    const double t = 0.1 * i, x = t <= 40.0 ? t : 80.0 - t;
    out << t << ' ' << x << " 0 0 " << (t <= 40.0 ? "0 0 0 1" : "0 0 1 0") << '\n';
  }
}

std::string information() {
  std::string s = "[";
  for (int i = 0; i < 36; ++i) s += std::string(i ? "," : "") + (i % 7 == 0 ? "400" : "0");
  return s + "]";
}

// Keyframe 60 (x = 20, facing -x) closes on keyframe 20 (x = 20, facing +x):
// T_20⁻¹·T_60 is a half turn in place; `dx` is added to its measured x.
void write_session(const std::filesystem::path& dir, double dx) {
  std::ofstream kf(dir / "keyframes.tum");
  for (int k = 0; k <= 79; ++k) kf << k << ".0 0 0 0 0 0 0 1\n";  // the graph's poses are not judged
  std::ofstream(dir / "summary.json") << R"({"loops": {"enabled": true, "edges": [{"from": 20, "to": 60, "measurement": [)"
                                      << dx << R"(, 0, 0, 0, 0, 1, 0], "information": )" << information() << "}]}}";
}

std::string arguments(const TempFolder& session, const TempFolder& truth) {
  return "loops --session '"s + session.path().string() + "' --truth '" + (truth.path() / "truth_body.tum").string() + "'";
}

TEST(AditEvalLoops, FiguresOfAHandMadeSession) {
  const TempFolder session, truth;
  write_truth(truth.path() / "truth_body.tum", 80.0);
  write_session(session.path(), 0.0);
  const EvalRun run = adit_eval(arguments(session, truth) + " --json");
  ASSERT_EQ(run.status, 0) << run.output;
  const auto j = nlohmann::json::parse(run.output);
  // Keyframes 54..79 lie within 3 m of the way out ≥ 30 m back along the path
  // (keyframe 54 at x = 26 is 2 m from keyframe 24, 30 m back; 53 is 4 m off 23).
  EXPECT_EQ(j["revisit_keyframes"].get<int>(), 26);
  EXPECT_EQ(j["accepted"].get<int>(), 1);
  EXPECT_EQ(j["false_accepted"].get<int>(), 0);
  EXPECT_DOUBLE_EQ(j["precision"].get<double>(), 1.0);
  EXPECT_EQ(j["recalled_keyframes"].get<int>(), 11);  // 55..65
  EXPECT_NEAR(j["loops"][0]["error_m"].get<double>(), 0.0, 1e-9);
  EXPECT_NEAR(j["loops"][0]["truth_path_m"].get<double>(), 40.0, 1e-9);

  write_session(session.path(), 0.5);  // measured 0.5 m off: false
  const EvalRun off = adit_eval(arguments(session, truth));
  ASSERT_EQ(off.status, 0) << off.output;
  EXPECT_NE(off.output.find("precision          0.0 %"), std::string::npos) << off.output;
  EXPECT_NE(off.output.find("FALSE"), std::string::npos) << off.output;
}

TEST(AditEvalLoops, BadInputExits2NamingTheFile) {
  const TempFolder session, truth;
  write_truth(truth.path() / "truth_body.tum", 60.0);  // shorter than the keyframes
  write_session(session.path(), 0.0);
  const EvalRun outside = adit_eval(arguments(session, truth));
  EXPECT_EQ(outside.status, 2) << outside.output;
  EXPECT_NE(outside.output.find("truth_body.tum"), std::string::npos) << outside.output;
  EXPECT_NE(outside.output.find("outside the truth"), std::string::npos) << outside.output;

  std::ofstream(session.path() / "summary.json") << R"({"loops": {"enabled": true, "edges": [)";
  const EvalRun bad_json = adit_eval(arguments(session, truth));
  EXPECT_EQ(bad_json.status, 2) << bad_json.output;
  EXPECT_NE(bad_json.output.find("summary.json"), std::string::npos) << bad_json.output;

  std::filesystem::remove(session.path() / "summary.json");
  const EvalRun missing = adit_eval(arguments(session, truth));
  EXPECT_EQ(missing.status, 2) << missing.output;
  EXPECT_NE(missing.output.find("summary.json"), std::string::npos) << missing.output;
}

}  // namespace
}  // namespace adit
