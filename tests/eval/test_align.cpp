#include <gtest/gtest.h>

#include "adit/eval/align.hpp"

namespace adit::eval {
namespace {
using slam::Pose;
using slam::Trajectory;

Eigen::Matrix3Xd some_points() {
  Eigen::Matrix3Xd p(3, 5);
  p << 0, 1, 0, 0, 2,  //
      0, 0, 1, 0, 3,   //
      0, 0, 0, 1, -1;
  return p;
}

TEST(Umeyama, RecoversKnownSimilarity) {
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(10, -4, 2);
  const double s = 1.25;
  const Eigen::Matrix3Xd from = some_points();
  const Eigen::Matrix3Xd to = (s * r * from).colwise() + t;
  const auto fit = umeyama_fit(from, to, true);
  ASSERT_TRUE(fit);
  EXPECT_TRUE(fit->rotation.isApprox(r, 1e-12));
  EXPECT_TRUE(fit->translation.isApprox(t, 1e-12));
  EXPECT_NEAR(fit->scale, s, 1e-12);
}

TEST(Umeyama, RigidFitKeepsUnitScale) {
  const Eigen::Matrix3d r = Eigen::AngleAxisd(-1.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3Xd from = some_points();
  const Eigen::Matrix3Xd to = (r * from).colwise() + Eigen::Vector3d(1, 2, 3);
  const auto fit = umeyama_fit(from, to, false);
  ASSERT_TRUE(fit);
  EXPECT_DOUBLE_EQ(fit->scale, 1.0);
  EXPECT_TRUE(fit->rotation.isApprox(r, 1e-12));
}

TEST(Umeyama, NeverReturnsAReflection) {
  // A mirrored copy: the best proper rotation, det = +1 (Umeyama eq. 39).
  Eigen::Matrix3Xd from = some_points();
  Eigen::Matrix3Xd to = from;
  to.row(2) *= -1.0;
  const auto fit = umeyama_fit(from, to, false);
  ASSERT_TRUE(fit);
  EXPECT_NEAR(fit->rotation.determinant(), 1.0, 1e-12);
}

TEST(Umeyama, CollinearOrTooFewPointsAreDegenerate) {
  Eigen::Matrix3Xd line(3, 4);
  line << 0, 1, 2, 3, 0, 2, 4, 6, 0, 0.5, 1, 1.5;
  EXPECT_FALSE(umeyama_fit(line, line, false));
  EXPECT_FALSE(umeyama_fit(some_points().leftCols(2), some_points().leftCols(2), false));
  const Eigen::Matrix3Xd same = Eigen::Matrix3Xd::Ones(3, 4);
  EXPECT_FALSE(umeyama_fit(same, same, true));
}

TEST(AlignTrajectory, OriginMovesFirstPoseOntoReference) {
  Pose a = Pose::Identity(), b = Pose::Identity();
  a.translation() = Eigen::Vector3d(1, 2, 3);
  b.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  b.translation() = Eigen::Vector3d(-5, 0, 1);
  const std::vector<Pose> ref{a, a}, est{b, b};
  const auto fit = align_trajectory(ref, est, Alignment::origin);
  ASSERT_TRUE(fit);
  EXPECT_TRUE(fit->apply(b).isApprox(a, 1e-12));
}

}  // namespace
}  // namespace adit::eval
