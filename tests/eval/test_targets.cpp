// Total-station target checks on small cases computed by hand.

#include <cmath>

#include <gtest/gtest.h>

#include "adit/common/error.hpp"
#include "adit/eval/targets.hpp"
#include "adit/eval/targets_io.hpp"
#include "temp_file.hpp"

namespace adit::eval {
namespace {
using slam::Pose;
using slam::Trajectory;

std::vector<Target> square(double half, double z = 0.0) {
  return {{"A", {-half, -half, z}}, {"B", {half, -half, z}}, {"C", {half, half, z}}, {"D", {-half, half, z}}};
}

TEST(Targets, ScaleErrorUnderRigidAndSimilarityFits) {
  // The map is 1 % too large: consecutive sides 20 m true, 20.2 m in the map.
  const std::vector<Target> truth = square(10.0);
  const std::vector<Target> map = square(10.1);
  const TargetReport rigid = evaluate_targets(truth, map, {}, false);
  ASSERT_EQ(rigid.distances.size(), 3u);
  EXPECT_NEAR(rigid.distances[0].error, -0.2, 1e-12);
  EXPECT_NEAR(rigid.distances[0].rate, -0.01, 1e-12);
  EXPECT_NEAR(rigid.distance_rmse, 0.2, 1e-12);
  EXPECT_NEAR(rigid.rate_rmse, 0.01, 1e-12);
  // Symmetry: the rigid fit is the identity, each corner is 0.1 sqrt(2) m off.
  EXPECT_TRUE(rigid.fit.rotation.isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  EXPECT_NEAR(rigid.fit.translation.norm(), 0.0, 1e-12);
  for (const PointError& p : rigid.points) EXPECT_NEAR(p.distance, 0.1 * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(rigid.points[0].delta.x(), 0.1, 1e-12);  // true -10 minus map -10.1
  EXPECT_NEAR(rigid.rmse_xyz.x(), 0.1, 1e-12);
  EXPECT_NEAR(rigid.rmse_xyz.z(), 0.0, 1e-12);
  EXPECT_NEAR(rigid.rmse_distance, 0.1 * std::sqrt(2.0), 1e-12);

  const TargetReport similarity = evaluate_targets(truth, map, {}, true);
  EXPECT_NEAR(similarity.fit.scale, 1.0 / 1.01, 1e-12);
  EXPECT_NEAR(similarity.rmse_distance, 0.0, 1e-9);
}

TEST(Targets, SimilarityFitRecoversKnownTransform) {
  // Map frame = survey frame turned 30 degrees about z, shifted, scaled by 0.8.
  const std::vector<Target> truth{{"T1", {100, 200, 10}},
                                  {"T2", {130, 210, 12}},
                                  {"T3", {120, 250, 9}},
                                  {"T4", {90, 240, 15}},
                                  {"T5", {110, 225, 30}}};
  const Eigen::Matrix3d r = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d t(1000, -500, 50);
  const double s = 0.8;
  std::vector<Target> map;
  for (const Target& x : truth) map.push_back({x.id, s * r * x.position + t});
  const TargetReport report = evaluate_targets(truth, map, {"T1", "T2", "T3", "T4"}, true);
  EXPECT_NEAR(report.fit.scale, 1.0 / s, 1e-12);
  EXPECT_TRUE(report.fit.rotation.isApprox(r.transpose(), 1e-12));
  EXPECT_NEAR(report.rmse_distance, 0.0, 1e-9);
  EXPECT_FALSE(report.points[4].control);
  // Every map distance is 0.8 of the true one: rate 1 - 0.8 = 0.2.
  for (const DistanceError& d : report.distances) EXPECT_NEAR(d.rate, 0.2, 1e-12);
  for (const LeaveOneOut& l : report.leave_one_out) {
    ASSERT_TRUE(l.error) << l.id;
    EXPECT_NEAR(l.error->distance, 0.0, 1e-9) << l.id;
  }
}

TEST(Targets, CheckTargetResidualAndLeaveOneOut) {
  // A, B, C are exact; D, a check target, sits 5 cm high in the map.
  const std::vector<Target> truth{{"A", {0, 0, 0}}, {"B", {10, 0, 0}}, {"C", {0, 10, 0}}, {"D", {10, 10, 1}}};
  std::vector<Target> map = truth;
  map[3].position.z() += 0.05;
  const TargetReport report = evaluate_targets(truth, map, {"A", "B", "C"}, false);
  EXPECT_TRUE(report.points[3].delta.isApprox(Eigen::Vector3d(0, 0, -0.05), 1e-12));
  EXPECT_NEAR(report.points[0].distance, 0.0, 1e-12);
  EXPECT_NEAR(report.rmse_xyz.z(), 0.025, 1e-12);  // sqrt(0.05^2 / 4)
  // A, B and C leave only two targets: no fit. D was never in it.
  EXPECT_FALSE(report.leave_one_out[0].error);
  ASSERT_TRUE(report.leave_one_out[3].error);
  EXPECT_NEAR(report.leave_one_out[3].error->distance, 0.05, 1e-12);
  // C -> D distance: true sqrt(100 + 1), map with 1.05 in z.
  EXPECT_NEAR(report.distances[2].error, std::sqrt(101.0) - std::sqrt(100.0 + 1.05 * 1.05), 1e-12);
}

TEST(Targets, LeaveOneOutWithFourControls) {
  // Fitting on the three exact targets leaves D's full offset.
  const std::vector<Target> truth{{"A", {0, 0, 0}}, {"B", {10, 0, 0}}, {"C", {0, 10, 0}}, {"D", {10, 10, 1}}};
  std::vector<Target> map = truth;
  map[3].position.x() += 0.04;
  const TargetReport report = evaluate_targets(truth, map, {}, false);
  ASSERT_TRUE(report.leave_one_out[3].error);
  EXPECT_TRUE(report.leave_one_out[3].error->delta.isApprox(Eigen::Vector3d(-0.04, 0, 0), 1e-9));
  // With D in the fit its residual is smaller than when it is left out.
  EXPECT_LT(report.points[3].distance, 0.04);
}

TEST(Targets, BadControlSetsAreInputErrors) {
  const std::vector<Target> truth = square(10.0);
  EXPECT_THROW(evaluate_targets(truth, truth, {"A", "B"}, false), InputError);
  EXPECT_THROW(evaluate_targets(truth, truth, {"A", "B", "X"}, false), InputError);
  EXPECT_THROW(evaluate_targets(truth, truth, {"A", "B", "B"}, false), InputError);
  const std::vector<Target> line{{"P", {0, 0, 0}}, {"Q", {5, 1, 0}}, {"R", {10, 2, 0}}, {"S", {20, 4, 0}}};
  try {
    evaluate_targets(line, line, {}, false);
    FAIL() << "collinear control targets accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("one line"), std::string::npos) << e.what();
  }
}

TEST(TargetsCsv, ReadsAndRejectsBadLines) {
  const test::TempFile good("id,x,y,z\nCP1, 1.5, 2, -3\nCP2,4,5,6\n", ".csv");
  const auto targets = read_targets_csv(good.path());
  ASSERT_EQ(targets.size(), 2u);
  EXPECT_EQ(targets[0].id, "CP1");
  EXPECT_TRUE(targets[0].position.isApprox(Eigen::Vector3d(1.5, 2, -3)));

  const test::TempFile bad_number("id,x,y,z\nCP1,1,2,3\nCP2,4,five,6\n", ".csv");
  try {
    read_targets_csv(bad_number.path());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), bad_number.path().string() + ":3");
  }
  const test::TempFile duplicate("id,x,y,z\nCP1,1,2,3\nCP1,4,5,6\n", ".csv");
  EXPECT_THROW(read_targets_csv(duplicate.path()), InputError);
  const test::TempFile no_header("CP1,1,2,3\n", ".csv");
  EXPECT_THROW(read_targets_csv(no_header.path()), InputError);
  const test::TempFile short_line("id,x,y,z\nCP1,1,2\n", ".csv");
  EXPECT_THROW(read_targets_csv(short_line.path()), InputError);
}

}  // namespace
}  // namespace adit::eval
