// The loop-closure stage on its own thread: keyframes pushed from another
// thread (as the mapping thread does), the graph closed in the background,
// the correction read after finish(). Listed in .ci/run's tsan_tests.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "../slam/loop_scenes.hpp"
#include "adit/daemon/loop_closure_stage.hpp"

namespace adit::daemon {
namespace {

using slam::test::pose_at;

constexpr float kSide = 20.0F;

// 1.25 laps of an 80 m ring, the map's poses 1 % long and turning 0.05° per
// metre too far: pushed from a producer thread that never waits for the stage.
TEST(LoopClosureStage, ClosesLoopsInTheBackgroundAndPublishesTheCorrection) {
  const std::vector<Eigen::Vector3f> world = slam::test::ring_corridor(kSide, 30, 23, 20.0F);
  config::Config config;
  PipelineStats stats;
  std::atomic<bool> stop{false};
  LoopClosureStage stage(config, stats, stop);
  stage.start();
  Eigen::Isometry3d odometry = slam::test::ring_pose(kSide, 0.0);
  Eigen::Isometry3d truth_end;
  std::vector<double> push_ms;
  std::thread producer([&] {
    const double step = 2.0;
    for (int k = 0; k * step <= 1.25 * 4 * kSide; ++k) {
      const Eigen::Isometry3d truth = slam::test::ring_pose(kSide, k * step);
      if (k > 0) {
        const Eigen::Isometry3d motion = slam::test::ring_pose(kSide, (k - 1) * step).inverse() * truth;
        odometry = odometry * motion * pose_at(0.01 * motion.translation().norm(), 0.0, 0.05 * M_PI / 180 * step);
      }
      KeyframeItem item{static_cast<std::int64_t>(k) * 1'000'000'000, odometry,
                        slam::test::scan_of(world, truth, 300 + static_cast<unsigned>(k))};
      const auto t0 = std::chrono::steady_clock::now();
      stage.input().push(std::move(item));
      push_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      truth_end = truth;
    }
  });
  producer.join();
  stage.finish();
  const slam::LoopCloser& closer = stage.closer();
  EXPECT_EQ(stats.loop_keyframes.load(), closer.poses().size());
  EXPECT_GE(stats.loops_accepted.load(), 3U);
  EXPECT_EQ(stats.loops_accepted.load(), closer.stats().accepted);
  // Loops found within map.loops_optimize_every_s of a solve wait for the next
  // (decision 062); finish() refines the graph with those still waiting.
  EXPECT_EQ(loop_closure_config(config).optimize_every_s, config.map.loops_optimize_every_s);
  EXPECT_GT(config.map.loops_optimize_every_s, 0.0);
  EXPECT_LT(closer.stats().optimizations, closer.stats().accepted);
  EXPECT_EQ(closer.unsolved(), 0U);
  const double before = (odometry.translation() - truth_end.translation()).norm();
  const double after = (closer.poses().back().translation() - truth_end.translation()).norm();
  EXPECT_LT(after, 0.5 * before);
  // The correction, applied to the newest map pose, gives the graph's.
  const slam::CorrectionTrack track = stage.correction();
  EXPECT_TRUE((track.at(closer.stamps().back()) * odometry).isApprox(closer.poses().back(), 1e-9));
  EXPECT_GT(track.max_translation_m(), 0.1);
  for (double ms : push_ms) EXPECT_LT(ms, 50.0);  // a push never waits for the graph
}

// 40 keyframes already waiting when the thread starts (a core too slow for the
// graph): behind a live source the stage adds them without a loop search until
// no more than kMaxKeyframesBehind wait, then searches again; a replay
// searches every one. Every keyframe is in the graph either way.
TEST(LoopClosureStage, BehindALiveSourceKeyframesJoinUnsearchedUntilTheQueueIsShort) {
  const std::vector<Eigen::Vector3f> world = slam::test::ring_corridor(kSide, 30, 23, 20.0F);
  const auto run = [&](bool live) {
    config::Config config;
    PipelineStats stats;
    std::atomic<bool> stop{false};
    LoopClosureStage stage(config, stats, stop, slam::LoopClosureConfig{}, live);
    for (int k = 0; k < 40; ++k) {
      const Eigen::Isometry3d pose = slam::test::ring_pose(kSide, 2.0 * k);
      stage.input().push({static_cast<std::int64_t>(k) * 1'000'000'000, pose,
                          slam::test::scan_of(world, pose, 700 + static_cast<unsigned>(k))});
    }
    stage.start();
    stage.finish();
    EXPECT_EQ(stage.closer().poses().size(), 40U);
    return stage.closer().stats();
  };
  const slam::LoopClosureStats live = run(true);
  EXPECT_EQ(live.keyframes_not_searched, 40 - 1 - kMaxKeyframesBehind);  // until 10 wait behind the one in hand
  EXPECT_EQ(run(false).keyframes_not_searched, 0U);
}

// Stopped at once (request_stop): the thread ends without draining or refining.
TEST(LoopClosureStage, StopsAtOnce) {
  config::Config config;
  PipelineStats stats;
  std::atomic<bool> stop{false};
  LoopClosureStage stage(config, stats, stop);
  stage.start();
  stop.store(true);
  stage.finish();
  EXPECT_EQ(stage.closer().stats().keyframes, 0U);
}

}  // namespace
}  // namespace adit::daemon
