// Loop closure on the real 64-beam sequence (../shared/data/sequences/hdl64-urban-22):
// 22 scans of a car driving 17 m straight through town; it never revisits.
// The scans go through the odometry, keyframes are taken as the mapping stage
// takes them (1 m or 10°, 0.2 m voxels) and fed to slam::LoopCloser.
//
// With the closer's settings no candidate can arise: keyframes must lie 30 m
// apart along the path and the car drives 17 m. That is the check, kept
// here; the second test makes it bite: with the minimum cut to 3 m, keyframes
// 3-17 m apart on the same street become candidates (real overlap), and every
// loop the closer accepts must agree with the odometry's relative pose (which
// follows GICP to 10 % of the path, test_odometry_realdata.cpp) within 0.3 m
// and 1°: verification on real scans accepts no wrong measurement.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "adit/drivers/lidar/scan_directory.hpp"
#include "adit/slam/keyframes.hpp"
#include "adit/slam/loop_closer.hpp"
#include "adit/slam/odometry.hpp"
#include "adit/slam/voxel_downsample.hpp"
#include "shared_data.hpp"

namespace adit::slam {
namespace {

std::vector<Keyframe> hdl64_keyframes(const std::filesystem::path& dir) {
  drivers::ScanDirectorySource source(dir);
  Odometry odometry{OdometryConfig{}};
  KeyframeSelector selector({1.0, 10.0});
  VoxelDownsampler downsampler(200'000);
  drivers::LidarScan scan;
  std::vector<Eigen::Vector3f> points;
  std::vector<Keyframe> keyframes;
  while (source.next(scan)) {
    points.clear();
    for (const drivers::LidarPoint& p : scan.points) points.emplace_back(p.x, p.y, p.z);
    const OdometryResult r = odometry.process({scan.start_time_ns, points, {}});
    EXPECT_TRUE(r.valid) << to_string(r.status);
    if (!r.valid || !selector.take(r.pose)) continue;
    Keyframe k{scan.start_time_ns, r.pose, {}};
    k.points.reserve(points.size());
    downsampler.downsample(points, 0.2F, k.points);
    keyframes.push_back(std::move(k));
  }
  return keyframes;
}

TEST(LoopClosureRealdata, NoLoopOnTheHdl64SequenceWhichNeverRevisits) {
  ADIT_REQUIRE_SHARED_DATA(dir, "sequences/hdl64-urban-22");
  const std::vector<Keyframe> keyframes = hdl64_keyframes(dir);
  ASSERT_GE(keyframes.size(), 10U);  // one a metre or more (two scans) over 17 m
  LoopCloser closer;
  for (const Keyframe& k : keyframes) closer.add_keyframe(k.stamp_ns, k.pose, k.points);
  EXPECT_EQ(closer.stats().keyframes, keyframes.size());
  EXPECT_EQ(closer.stats().accepted, 0U);
  EXPECT_EQ(closer.graph().loop_count(), 0U);
  // The graph is the odometry's: nothing moved.
  EXPECT_LT((closer.poses().back().translation() - keyframes.back().pose.translation()).norm(), 1e-6);
}

// With the settings given, the closer's loops on this sequence, checked against
// the odometry's relative poses; returns the count accepted.
std::size_t loops_agreeing_with_odometry(const std::vector<Keyframe>& keyframes, const LoopClosureConfig& config,
                                         const char* name) {
  LoopCloser closer(config);
  for (const Keyframe& k : keyframes) closer.add_keyframe(k.stamp_ns, k.pose, k.points);
  const LoopClosureStats& s = closer.stats();
  std::printf("hdl64-urban-22, %s: %zu keyframes, %zu candidates, %zu verified (%zu partial), %zu accepted\n", name,
              s.keyframes, s.candidates, s.verified, s.partial, s.accepted);
  for (const LoopEvent& e : closer.events())
    std::printf("  %zu -> %zu: %s, descriptor %.3f, inliers %.2f, rms %.3f m, conditioning %.4f\n", e.candidate, e.query,
                e.outcome.c_str(), e.descriptor_distance, e.inlier_ratio, e.rmse_m, e.conditioning);
  EXPECT_GT(s.candidates, 0U) << name << ": no candidate, the check would not bite";
  double worst_m = 0.0, worst_deg = 0.0;
  for (const PoseGraphEdge& e : closer.graph().edges) {
    if (e.kind != EdgeKind::loop) continue;
    const Eigen::Isometry3d odometry = keyframes[e.from].pose.inverse() * keyframes[e.to].pose;
    const Eigen::Isometry3d error = e.measurement.inverse() * odometry;
    const double deg = Eigen::AngleAxisd(error.linear()).angle() * 180.0 / M_PI;
    EXPECT_LT(error.translation().norm(), 0.3) << name << ": " << e.from << " -> " << e.to;
    EXPECT_LT(deg, 1.0) << name << ": " << e.from << " -> " << e.to;
    worst_m = std::max(worst_m, error.translation().norm());
    worst_deg = std::max(worst_deg, deg);
  }
  std::printf("  accepted loops against the odometry: worst %.3f m, %.3f deg\n", worst_m, worst_deg);
  return s.accepted;
}

TEST(LoopClosureRealdata, LoopsAcceptedAlongTheSameStreetAgreeWithTheOdometry) {
  ADIT_REQUIRE_SHARED_DATA(dir, "sequences/hdl64-urban-22");
  const std::vector<Keyframe> keyframes = hdl64_keyframes(dir);
  LoopClosureConfig config;
  config.search.min_path_separation_m = 3.0;
  config.search.base_radius_m = 8.0;  // the gate would otherwise keep only keyframes about 3 m away
  // The submap holds only keyframes ≥ 3 m behind the query, which sees 80 m
  // ahead: 15-37 % of its points find a partner (fit 2 cm), under the 60 % the
  // closer asks, so none is verified. With 10 % the fits are let through and
  // what the guard accepts is checked.
  loops_agreeing_with_odometry(keyframes, config, "3 m minimum");
  config.verification.min_inlier_ratio = 0.1;
  EXPECT_GT(loops_agreeing_with_odometry(keyframes, config, "3 m minimum, 10 % inliers"), 0U);
}

}  // namespace
}  // namespace adit::slam
