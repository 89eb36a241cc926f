// The one TUM writer: stamps from whole nanoseconds (a double would round a
// Unix time to 0.2 µs), positions to 1 µm, the unit quaternion to 9 decimals.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "adit/common/error.hpp"
#include "adit/slam/tum.hpp"
#include "shared_data.hpp"

namespace adit::slam {
namespace {

Pose turned_and_moved() {
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::AngleAxisd(M_PI / 2.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(1.5, -2.25, 0.0000004);
  return pose;
}

TEST(TumWriter, WritesUnixStampsToTheNanosecond) {
  const std::filesystem::path file = test::binary_dir() / "tum-writer" / "trajectory.tum";
  {
    TumWriter out(file);
    out.write(1'767'225'600'012'345'678, turned_and_moved());
    out.write(-1'500'000'000, Pose::Identity());
    EXPECT_TRUE(out.flush());
  }
  std::ifstream in(file);
  std::string first;
  std::string second;
  std::getline(in, first);
  std::getline(in, second);
  EXPECT_EQ(first, "1767225600.012345678 1.500000 -2.250000 0.000000 0.000000000 0.000000000 0.707106781 0.707106781");
  EXPECT_EQ(second, "-1.500000000 0.000000 0.000000 0.000000 0.000000000 0.000000000 0.000000000 1.000000000");
  std::filesystem::remove_all(file.parent_path());
}

TEST(TumWriter, TrajectoriesRoundTheirStampsToTheNanosecond) {
  Trajectory trajectory;
  trajectory.push_back(12.000000001, turned_and_moved());
  std::ostringstream out;
  write_tum(out, trajectory);
  EXPECT_EQ(out.str(), "12.000000001 1.500000 -2.250000 0.000000 0.000000000 0.000000000 0.707106781 0.707106781\n");
}

TEST(TumWriter, NamesAFileItCannotWrite) {
  try {
    TumWriter out("/proc/adit-cannot-write/trajectory.tum");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "/proc/adit-cannot-write/trajectory.tum");
  }
}

}  // namespace
}  // namespace adit::slam
