// Loop detection against the truth (eval/loop_truth.hpp) and the reader of
// aditd's accepted loops (eval/loop_summary_io.hpp), on a hand-made square.

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "adit/common/error.hpp"
#include "adit/eval/loop_summary_io.hpp"
#include "adit/eval/loop_truth.hpp"

namespace adit::eval {
namespace {

// A 10 m square driven at 1 m/s from (0,0) along +x, +y, -x, -y, facing the
// way it drives; the truth at 10 Hz for `seconds`.
slam::Pose square_pose(double s) {
  const double u = std::fmod(s, 40.0);
  const int side = static_cast<int>(u / 10.0);
  const double f = u - 10.0 * side;
  const Eigen::Vector2d corners[4] = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  const Eigen::Vector2d dirs[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
  slam::Pose p = slam::Pose::Identity();
  p.translation() << corners[side] + f * dirs[side], 0.0;
  p.linear() = Eigen::AngleAxisd(M_PI / 2 * side, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return p;
}

slam::Trajectory square_truth(double seconds) {
  slam::Trajectory t;
  for (int i = 0; i <= static_cast<int>(seconds * 10); ++i) t.push_back(0.1 * i, square_pose(0.1 * i));
  return t;
}

std::vector<double> keyframe_stamps(int count) {  // one per second: one per metre
  std::vector<double> s;
  for (int k = 0; k < count; ++k) s.push_back(static_cast<double>(k));
  return s;
}

LoopEdgeRecord loop_of(const KeyframeTruth& truth, std::size_t from, std::size_t to) {
  LoopEdgeRecord r;
  r.from = from;
  r.to = to;
  r.measurement = truth.poses[from].inverse() * truth.poses[to];
  r.information = slam::Matrix6d::Identity() * 400.0;
  return r;
}

TEST(LoopTruth, KeyframesTakeTheTruthAndItsPathAtTheirStamps) {
  const slam::Trajectory truth = square_truth(60.0);
  const std::vector<double> stamps{2.55, 12.0};
  const KeyframeTruth k = keyframe_truth(truth, stamps, "truth_body.tum");
  EXPECT_NEAR(k.poses[0].translation().x(), 2.55, 1e-9);
  EXPECT_NEAR(k.path_m[0], 2.55, 1e-9);
  EXPECT_NEAR(k.poses[1].translation().y(), 2.0, 1e-9);
  EXPECT_NEAR(k.path_m[1], 12.0, 1e-9);
}

TEST(LoopTruth, AStampOutsideTheTruthNamesTheTruthFile) {
  const slam::Trajectory truth = square_truth(10.0);
  const std::vector<double> stamps{1.0, 10.5};
  try {
    keyframe_truth(truth, stamps, "truth_body.tum");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "truth_body.tum");
    EXPECT_NE(std::string(e.what()).find("keyframe 1"), std::string::npos) << e.what();
  }
}

TEST(LoopTruth, RevisitsAreCloseByAndFarBackAlongThePath) {
  const KeyframeTruth truth = keyframe_truth(square_truth(61.0), keyframe_stamps(61), "t");
  const LoopTruthReport r = evaluate_loops(truth, {}, {});
  // Keyframe 37 is at (0,3), 3 m from the start and 37 m along; 36 is 4 m off.
  ASSERT_EQ(r.revisit_keyframes.size(), 24u);
  EXPECT_EQ(r.revisit_keyframes.front(), 37u);
  ASSERT_EQ(r.revisit_stretches.size(), 1u);
  EXPECT_EQ(r.revisit_stretches[0].first, 37u);
  EXPECT_EQ(r.revisit_stretches[0].last, 60u);
  EXPECT_FALSE(r.precision.has_value());  // nothing accepted
  EXPECT_DOUBLE_EQ(*r.recall, 0.0);
  // Within 5 m: from keyframe 35, at (0,5).
  LoopTruthConfig wider;
  wider.revisit_m = 5.0;
  EXPECT_EQ(evaluate_loops(truth, {}, wider).revisit_keyframes.front(), 35u);
}

TEST(LoopTruth, FalseLoopsPrecisionRecallAndError) {
  const KeyframeTruth truth = keyframe_truth(square_truth(61.0), keyframe_stamps(61), "t");
  std::vector<LoopEdgeRecord> loops;
  loops.push_back(loop_of(truth, 5, 45));  // exact
  LoopEdgeRecord wrong = loop_of(truth, 10, 48);
  wrong.measurement = slam::Pose::Identity();  // 2 m off
  loops.push_back(wrong);
  LoopEdgeRecord partial = loop_of(truth, 20, 60);  // 1 m off along its free axis (x of keyframe 20)
  partial.measurement.translation().x() += 1.0;
  partial.information(0, 0) = 0.0;
  loops.push_back(partial);
  LoopEdgeRecord turned = loop_of(truth, 0, 40);  // 2° off
  turned.measurement.linear() = turned.measurement.linear() * Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  loops.push_back(turned);

  const LoopTruthReport r = evaluate_loops(truth, loops, {});
  ASSERT_EQ(r.loops.size(), 4u);
  EXPECT_FALSE(r.loops[0].is_false);
  EXPECT_NEAR(r.loops[0].error_m, 0.0, 1e-9);
  EXPECT_TRUE(r.loops[1].is_false);
  EXPECT_NEAR(r.loops[1].error_m, 2.0, 1e-9);
  EXPECT_TRUE(r.loops[2].partial);
  EXPECT_FALSE(r.loops[2].is_false);
  EXPECT_NEAR(r.loops[2].error_m, 1.0, 1e-9);
  EXPECT_NEAR(r.loops[2].error_judged_m, 0.0, 1e-9);
  EXPECT_TRUE(r.loops[3].is_false);
  EXPECT_NEAR(r.loops[3].error_deg, 2.0, 1e-6);
  EXPECT_EQ(r.false_loops, 2u);
  EXPECT_DOUBLE_EQ(*r.precision, 0.5);
  // True queries 45 and 60 cover revisits 40..50 and 55..60: 17 of 37..60.
  EXPECT_EQ(r.recalled_keyframes, 17u);
  EXPECT_NEAR(*r.recall, 17.0 / 24.0, 1e-12);
  EXPECT_EQ(r.recalled_stretches, 1u);
  EXPECT_EQ(r.error_m.count, 2u);
  EXPECT_NEAR(r.error_m.max, 0.0, 1e-9);

  // A loop between keyframes truly 14 m apart is false even if measured right.
  const std::vector<LoopEdgeRecord> far{loop_of(truth, 0, 60)};  // (0,0) and (10,10)
  EXPECT_EQ(evaluate_loops(truth, far, {}).false_loops, 1u);
  LoopTruthConfig loose;
  loose.false_beyond_m = 20.0;
  EXPECT_EQ(evaluate_loops(truth, far, loose).false_loops, 0u);
  // A loop naming a keyframe that does not exist.
  const std::vector<LoopEdgeRecord> beyond{loop_of(truth, 0, 40)};
  std::vector<LoopEdgeRecord> bad = beyond;
  bad[0].to = 61;
  EXPECT_THROW(evaluate_loops(truth, bad, {}, "summary.json"), InputError);
}

TEST(LoopTruth, FreeAxisIsTheInformationsNullTranslation) {
  slam::Matrix6d info = slam::Matrix6d::Identity() * 400.0;
  EXPECT_FALSE(free_axis(info).has_value());
  const Eigen::Vector3d w = Eigen::Vector3d(1, 1, 0).normalized();
  Eigen::Matrix<double, 6, 1> w6 = Eigen::Matrix<double, 6, 1>::Zero();
  w6.head<3>() = w;
  const slam::Matrix6d P = slam::Matrix6d::Identity() - w6 * w6.transpose();
  const std::optional<Eigen::Vector3d> axis = free_axis(P * info * P);
  ASSERT_TRUE(axis.has_value());
  EXPECT_NEAR(std::abs(axis->dot(w)), 1.0, 1e-9);
  info(5, 5) = 0.0;  // yaw free: not a partial loop's axis
  EXPECT_FALSE(free_axis(info).has_value());
}

std::string summary_with(const std::string& edges) {
  return R"({"loops": {"enabled": true, "accepted": 1, "edges": )" + edges + "}}";
}

std::string identity_information() {
  std::string s = "[";
  for (int i = 0; i < 36; ++i) s += std::string(i ? "," : "") + (i % 7 == 0 ? "400" : "0");
  return s + "]";
}

TEST(LoopSummary, ReadsTheGraphsLoops) {
  std::istringstream in(summary_with(R"([{"from": 3, "to": 70, "measurement": [1, 2, 3, 0, 0, 0.7071067811865476, 0.7071067811865476], "information": )" +
                                     identity_information() + "}]"));
  const std::vector<LoopEdgeRecord> loops = read_loop_edges(in, "summary.json");
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_EQ(loops[0].from, 3u);
  EXPECT_EQ(loops[0].to, 70u);
  EXPECT_NEAR(loops[0].measurement.translation().z(), 3.0, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(loops[0].measurement.linear()).angle(), M_PI / 2, 1e-9);
  EXPECT_DOUBLE_EQ(loops[0].information(5, 5), 400.0);
}

TEST(LoopSummary, BadInputNamesFileAndKey) {
  const auto key_of = [](const std::string& text) {
    std::istringstream in(text);
    try {
      read_loop_edges(in, "summary.json");
    } catch (const InputError& e) {
      EXPECT_EQ(e.where(), "summary.json");
      return e.key();
    }
    return std::string("no error");
  };
  EXPECT_EQ(key_of("{not json"), "");
  EXPECT_EQ(key_of(R"({"scans": {}})"), "loops");
  EXPECT_EQ(key_of(R"({"loops": {"enabled": false}})"), "loops.enabled");
  EXPECT_EQ(key_of(R"({"loops": {"enabled": true, "events": []}})"), "loops.edges");
  EXPECT_EQ(key_of(R"({"loops": {"enabled": 1, "edges": {}}})"), "loops.edges");
  EXPECT_EQ(key_of(R"({"loops": [1, 2]})"), "loops.edges");
  EXPECT_EQ(key_of(summary_with(R"([7])")), "loops.edges[0].from");
  EXPECT_EQ(key_of(summary_with(R"([{"from": -1, "to": 2}])")), "loops.edges[0].from");
  EXPECT_EQ(key_of(summary_with(R"([{"from": 1, "to": 2, "measurement": [0, 0, 0, 0, 0, 0, 0], "information": [1]}])")),
            "loops.edges[0].measurement");
  EXPECT_EQ(key_of(summary_with(R"([{"from": 1, "to": 2, "measurement": [0, 0, 0, 0, 0, 0, 1], "information": [1]}])")),
            "loops.edges[0].information");
}

}  // namespace
}  // namespace adit::eval
