// Odometry on the real 64-beam sequence (../shared/data/sequences/hdl64-urban-22).
// The sequence has no poses; PCL's GICP, run scan to scan on the same scans
// (`adit bench odometry --baseline-out`), finds the car 17.0 m along after 21
// scans, 0.74 m per scan from the first one, nearly straight. Without the
// start search, adit's odometry crept along at 0.1 m per scan here (1.98 m in
// all): its first prediction was "standing still" (docs/decisions/012-start-search.md).

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "adit/drivers/lidar/scan_directory.hpp"
#include "adit/slam/odometry.hpp"
#include "shared_data.hpp"

namespace adit::slam {
namespace {

TEST(OdometryRealdata, FollowsTheCarAlongTheHdl64SequenceAsGicpDoes) {
  ADIT_REQUIRE_SHARED_DATA(dir, "sequences/hdl64-urban-22");
  drivers::ScanDirectorySource source(dir);
  Odometry odometry{OdometryConfig{}};
  drivers::LidarScan scan;
  std::vector<Eigen::Vector3f> points;
  std::vector<Eigen::Vector3d> positions;
  while (source.next(scan)) {
    points.clear();
    for (const drivers::LidarPoint& p : scan.points) points.emplace_back(p.x, p.y, p.z);
    const OdometryResult r = odometry.process({scan.start_time_ns, points, {}});
    ASSERT_TRUE(r.valid) << "scan " << positions.size() << ": " << to_string(r.status);
    positions.push_back(r.pose.translation());
  }
  ASSERT_EQ(positions.size(), 22U);
  double path = 0.0;
  for (std::size_t i = 1; i < positions.size(); ++i) path += (positions[i] - positions[i - 1]).norm();
  // Within 10 % of GICP's 17.0 m (adit: 16.6 m), and forward, not sideways.
  EXPECT_NEAR(path, 17.0, 1.7);
  EXPECT_GT(positions.back().x(), 15.0) << positions.back().transpose();
  EXPECT_LT(std::abs(positions.back().y()), 1.0) << positions.back().transpose();
  // Every step is a car's at 20-35 km/h (GICP: 0.74-0.82 m), the first one included.
  for (std::size_t i = 1; i < positions.size(); ++i)
    EXPECT_NEAR((positions[i] - positions[i - 1]).norm(), 0.77, 0.25) << "scan " << i;  // adit: 0.61-0.82 m
}

}  // namespace
}  // namespace adit::slam
