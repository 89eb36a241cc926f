#include <sstream>

#include <gtest/gtest.h>

#include "adit/common/error.hpp"
#include "adit/eval/trajectory_io.hpp"
#include "adit/slam/tum.hpp"
#include "temp_file.hpp"

namespace adit::eval {
namespace {
using slam::Pose;
using slam::Trajectory;

using test::TempFile;

// The message of the InputError `read` throws, or "" when it does not throw.
template <typename Read>
std::string error_of(Read&& read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ReadTum, ReadsPosesAndNormalisesQuaternions) {
  const TempFile f("# comment\n1.0 1 2 3 0 0 0 2\n\n2.5 4 5 6 0 0 1 1\n");
  const Trajectory t = read_tum(f.path());
  ASSERT_EQ(t.size(), 2u);
  EXPECT_TRUE(t.timed);
  EXPECT_DOUBLE_EQ(t.stamps[1], 2.5);
  EXPECT_TRUE(t.poses[0].translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_TRUE(t.poses[0].linear().isApprox(Eigen::Matrix3d::Identity()));
  // 90 degrees about z: x goes to y.
  EXPECT_TRUE((t.poses[1].linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
}

TEST(ReadTum, MalformedLineNamesFileAndLine) {
  const TempFile f("1.0 1 2 3 0 0 0 1\n2.0 1 2 x 0 0 0 1\n");
  const std::string e = error_of([&] { read_tum(f.path()); });
  EXPECT_NE(e.find(f.path().string() + ":2"), std::string::npos) << e;
  EXPECT_NE(e.find("'x'"), std::string::npos) << e;
}

TEST(ReadTum, WrongFieldCountNamesLine) {
  const TempFile f("1.0 1 2 3 0 0 0 1\n\n2.0 1 2 3 0 0 1\n");
  const std::string e = error_of([&] { read_tum(f.path()); });
  EXPECT_NE(e.find(f.path().string() + ":3"), std::string::npos) << e;
}

TEST(ReadTum, TimeGoingBackwardsIsAnError) {
  const TempFile f("2.0 1 2 3 0 0 0 1\n1.0 1 2 3 0 0 0 1\n");
  const std::string e = error_of([&] { read_tum(f.path()); });
  EXPECT_NE(e.find(":2"), std::string::npos) << e;
  EXPECT_NE(e.find("backwards"), std::string::npos) << e;
}

TEST(ReadTum, ZeroQuaternionAndEmptyFileAreErrors) {
  const TempFile zero("1.0 1 2 3 0 0 0 0\n");
  EXPECT_NE(error_of([&] { read_tum(zero.path()); }).find("zero length"), std::string::npos);
  const TempFile empty("# nothing\n");
  EXPECT_NE(error_of([&] { read_tum(empty.path()); }).find("no poses"), std::string::npos);
  EXPECT_NE(error_of([&] { read_tum("/nonexistent/adit.txt"); }).find("cannot open"), std::string::npos);
}

TEST(ReadTum, FromAStreamErrorsNameTheGivenFile) {
  std::istringstream in("1.0 1 2 3 0 0 0 1\n0.5 1 2 3 0 0 0 1\n");
  const std::string e = error_of([&] { read_tum(in, "odometry.tum"); });
  EXPECT_NE(e.find("odometry.tum:2"), std::string::npos) << e;
}

TEST(ReadKitti, ReadsMatrixAndOptionalTimes) {
  const TempFile poses("1 0 0 5 0 1 0 6 0 0 1 7\n0 -1 0 1 1 0 0 2 0 0 1 3\n");
  const TempFile times("0.0\n0.1\n");
  const Trajectory untimed = read_kitti(poses.path());
  EXPECT_FALSE(untimed.timed);
  EXPECT_DOUBLE_EQ(untimed.stamps[1], 1.0);
  const Trajectory t = read_kitti(poses.path(), times.path());
  ASSERT_EQ(t.size(), 2u);
  EXPECT_TRUE(t.timed);
  EXPECT_DOUBLE_EQ(t.stamps[1], 0.1);
  EXPECT_TRUE(t.poses[0].translation().isApprox(Eigen::Vector3d(5, 6, 7)));
  EXPECT_DOUBLE_EQ(t.poses[1].linear()(0, 1), -1.0);
}

TEST(ReadKitti, BadLinesAndTimesAreErrors) {
  const TempFile short_line("1 0 0 5 0 1 0 6 0 0 1\n");
  EXPECT_NE(error_of([&] { read_kitti(short_line.path()); }).find(":1"), std::string::npos);
  const TempFile poses("1 0 0 5 0 1 0 6 0 0 1 7\n1 0 0 5 0 1 0 6 0 0 1 7\n");
  const TempFile backwards("0.2\n0.1\n");
  EXPECT_NE(error_of([&] { read_kitti(poses.path(), backwards.path()); }).find(backwards.path().string() + ":2"),
            std::string::npos);
  const TempFile too_few("0.0\n");
  EXPECT_NE(error_of([&] { read_kitti(poses.path(), too_few.path()); }).find("1 times for 2 poses"), std::string::npos);
}

TEST(ReadEurocCsv, ReadsNanosecondStampsAndWFirstQuaternions) {
  const TempFile f(
      "#timestamp,x,y,z,qw,qx,qy,qz,vx\n"
      "1403715524907143168,0.5,2.0,1.0,1,0,0,0,9\n"
      "1403715524912143104,0.6,2.0,1.0,0,0,0,1,9\n",
      ".csv");
  const Trajectory t = read_euroc_csv(f.path());
  ASSERT_EQ(t.size(), 2u);
  EXPECT_NEAR(t.stamps[1] - t.stamps[0], 0.005, 1e-6);
  EXPECT_TRUE(t.poses[0].linear().isApprox(Eigen::Matrix3d::Identity()));
  // w = 0, z = 1: 180 degrees about z.
  EXPECT_TRUE((t.poses[1].linear() * Eigen::Vector3d::UnitX()).isApprox(-Eigen::Vector3d::UnitX()));
  EXPECT_EQ(detect_trajectory_format(f.path()), TrajectoryFormat::euroc);
}

TEST(ReadEurocCsv, NonIntegerStampIsAnError) {
  const TempFile f("1.5e9,0.5,2.0,1.0,1,0,0,0\n", ".csv");
  EXPECT_NE(error_of([&] { read_euroc_csv(f.path()); }).find(":1"), std::string::npos);
}

TEST(WriteTum, RoundTrips) {
  Trajectory t;
  Pose p = Pose::Identity();
  p.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  p.translation() = Eigen::Vector3d(1.5, -2.25, 3.125);
  t.push_back(12.5, Pose::Identity());
  t.push_back(12.6, p);
  const TempFile f("");
  slam::write_tum(f.path(), t);
  EXPECT_EQ(detect_trajectory_format(f.path()), TrajectoryFormat::tum);
  const Trajectory back = read_tum(f.path());
  ASSERT_EQ(back.size(), 2u);
  EXPECT_NEAR(back.stamps[1], 12.6, 1e-9);
  EXPECT_TRUE(back.poses[1].isApprox(p, 1e-8));
}

TEST(DetectFormat, KittiAndUnknown) {
  const TempFile kitti("1 0 0 5 0 1 0 6 0 0 1 7\n");
  EXPECT_EQ(detect_trajectory_format(kitti.path()), TrajectoryFormat::kitti);
  const TempFile odd("1 2 3\n");
  EXPECT_NE(error_of([&] { detect_trajectory_format(odd.path()); }).find("format"), std::string::npos);
}

}  // namespace
}  // namespace adit::eval
