// The pose graph's path for clients (daemon/graph_path.hpp): where the graph
// puts each keyframe, its newest time on pose_t's clock, and a long session
// thinned evenly with both ends kept.
#include <gtest/gtest.h>

#include <vector>

#include "adit/daemon/graph_path.hpp"

namespace adit::daemon {
namespace {

Eigen::Isometry3d at(double x, double y, double yaw) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(x, y, 0.5);
  return t;
}

// `n` keyframes 1 m apart along x (odometry) that the graph bends toward +y.
slam::CorrectionTrack track_of(std::size_t n) {
  std::vector<std::int64_t> stamps;
  std::vector<Eigen::Isometry3d> graph, odometry;
  for (std::size_t k = 0; k < n; ++k) {
    const double x = static_cast<double>(k);
    stamps.push_back(1'000'000'000 + static_cast<std::int64_t>(k) * 100'000'000);  // 1 s, then every 0.1 s
    odometry.push_back(at(x, 0, 0));
    graph.push_back(at(x, 0.01 * x, 0.001 * x));
  }
  return slam::CorrectionTrack(stamps, graph, odometry);
}

TEST(GraphPath, EachKeyframeWhereTheGraphPutsItNotTheOdometry) {
  const GraphPath path = graph_path_of(track_of(5));
  ASSERT_EQ(path.positions.size(), 5U);
  EXPECT_EQ(path.n_keyframes, 5);
  EXPECT_EQ(path.utime, 1'400'000);  // the newest keyframe: 1.4 s in µs
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_FLOAT_EQ(path.positions[k][0], static_cast<float>(k));
    EXPECT_FLOAT_EQ(path.positions[k][1], 0.01F * static_cast<float>(k));
    EXPECT_FLOAT_EQ(path.positions[k][2], 0.5F);
  }
}

TEST(GraphPath, ALongSessionIsThinnedEvenlyWithBothEndsKept) {
  const slam::CorrectionTrack track = track_of(10001);
  const GraphPath path = graph_path_of(track, 4000);
  ASSERT_EQ(path.positions.size(), 4000U);
  EXPECT_EQ(path.n_keyframes, 10001);
  EXPECT_FLOAT_EQ(path.positions.front()[0], 0.0F);
  EXPECT_FLOAT_EQ(path.positions.back()[0], 10000.0F);
  // 10000 m in 3999 steps: each 2.5 m, give or take the rounding to a keyframe.
  for (std::size_t j = 1; j < path.positions.size(); ++j) {
    const float step = path.positions[j][0] - path.positions[j - 1][0];
    ASSERT_GE(step, 2.0F) << j;
    ASSERT_LE(step, 3.0F) << j;
  }
  EXPECT_EQ(graph_path_of(track, 20000).positions.size(), 10001U);  // room for all: all
}

TEST(GraphPath, NoKeyframesNoPath) {
  const GraphPath path = graph_path_of(slam::CorrectionTrack{});
  EXPECT_TRUE(path.positions.empty());
  EXPECT_EQ(path.n_keyframes, 0);
  EXPECT_EQ(graph_path_of(track_of(1)).positions.size(), 1U);
}

}  // namespace
}  // namespace adit::daemon
