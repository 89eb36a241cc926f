// The loop-closure stage on its own thread: keyframes pushed from another
// thread (as the mapping thread does), the graph closed in the background,
// the correction read after finish(). Listed in .ci/run's tsan_tests.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <optional>
#include <thread>

#include "../slam/loop_scenes.hpp"
#include "adit/daemon/loop_closure_stage.hpp"

namespace adit::daemon {
namespace {

using slam::test::pose_at;

constexpr float kSide = 20.0F;

// Pushes as the mapping thread does: waiting for room while the pipeline runs.
void push(LoopClosureStage& stage, KeyframeItem item) {
  stage.input().push(std::move(item), [] { return true; });
}

// 1.25 laps of an 80 m ring, the map's poses 1 % long and turning 0.05° per
// metre too far: pushed from a producer thread as fast as it goes, as a replay
// does, so it waits for the stage while kMaxKeyframesBehind keyframes wait.
TEST(LoopClosureStage, ClosesLoopsInTheBackgroundAndPublishesTheCorrection) {
  const std::vector<Eigen::Vector3f> world = slam::test::ring_corridor(kSide, 30, 23, 20.0F);
  config::Config config;
  PipelineStats stats;
  std::atomic<bool> stop{false};
  LoopClosureStage stage(config, stats, stop);
  stage.start();
  Eigen::Isometry3d odometry = slam::test::ring_pose(kSide, 0.0);
  Eigen::Isometry3d truth_end;
  std::size_t deepest = 0;
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
      push(stage, std::move(item));
      deepest = std::max(deepest, stage.input().depth());
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
  EXPECT_LE(deepest, kMaxKeyframesBehind);  // the producer waited for room
}

// 40 keyframes already waiting when the thread starts (a core too slow for the
// graph): behind a live source the stage adds them without a loop search until
// no more than kMaxKeyframesBehind wait, then searches again. A replay's
// producer waits for room instead, and every keyframe is searched. Every
// keyframe is in the graph either way.
TEST(LoopClosureStage, BehindALiveSourceKeyframesJoinUnsearchedUntilTheQueueIsShort) {
  const std::vector<Eigen::Vector3f> world = slam::test::ring_corridor(kSide, 30, 23, 20.0F);
  const auto run = [&](bool live) {
    config::Config config;
    PipelineStats stats;
    std::atomic<bool> stop{false};
    LoopClosureStage stage(config, stats, stop, slam::LoopClosureConfig{}, live);
    if (!live) stage.start();  // else its producer would wait for room before it starts
    for (int k = 0; k < 40; ++k) {
      const Eigen::Isometry3d pose = slam::test::ring_pose(kSide, 2.0 * k);
      push(stage, {static_cast<std::int64_t>(k) * 1'000'000'000, pose,
                   slam::test::scan_of(world, pose, 700 + static_cast<unsigned>(k))});
    }
    if (live)
      EXPECT_EQ(stage.input().depth(), 40U);
    else
      EXPECT_LE(stage.input().depth(), kMaxKeyframesBehind);
    if (live) stage.start();
    stage.finish();
    EXPECT_EQ(stage.closer().poses().size(), 40U);
    return stage.closer().stats();
  };
  const slam::LoopClosureStats live = run(true);
  EXPECT_EQ(live.keyframes_not_searched, 40 - 1 - kMaxKeyframesBehind);  // until 10 wait behind the one in hand
  EXPECT_EQ(run(false).keyframes_not_searched, 0U);
}

// Behind a replay (a capacity), a producer finding the queue full waits,
// beating its heartbeat (idle()) until one is taken; once the pipeline stops
// (idle() says false) it queues the keyframe anyway: none is ever dropped.
TEST(KeyframeQueue, AProducerWaitsForRoomBeatingUntilOneIsTakenOrThePipelineStops) {
  KeyframeQueue queue(2);
  for (int k = 0; k < 2; ++k) queue.push({k, Eigen::Isometry3d::Identity(), {}}, [] { return true; });
  std::atomic<int> beats{0};
  std::atomic<bool> stop{false};
  std::atomic<bool> pushed{false};
  const auto idle = [&] {
    beats.fetch_add(1);
    return !stop.load();
  };
  std::thread producer([&] {
    queue.push({2, Eigen::Isometry3d::Identity(), {}}, idle);
    pushed.store(true);
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_FALSE(pushed.load());
  EXPECT_EQ(queue.depth(), 2U);
  EXPECT_GE(beats.load(), 2);
  ASSERT_TRUE(queue.pop(std::chrono::milliseconds(0)).has_value());
  producer.join();  // woken by the room
  EXPECT_EQ(queue.depth(), 2U);

  std::thread stopped([&] { queue.push({3, Eigen::Isometry3d::Identity(), {}}, idle); });
  std::this_thread::sleep_for(std::chrono::milliseconds(150));
  stop.store(true);
  stopped.join();  // released within a poll
  EXPECT_EQ(queue.depth(), 3U);
  std::int64_t last = 0;  // the first was taken above
  while (std::optional<KeyframeItem> k = queue.pop(std::chrono::milliseconds(0))) {
    EXPECT_EQ(k->stamp_ns, last + 1);  // in order, none dropped
    last = k->stamp_ns;
  }
  EXPECT_EQ(last, 3);
}

// Without a capacity (behind a live source) a push never waits.
TEST(KeyframeQueue, WithoutACapacityAPushNeverWaits) {
  KeyframeQueue queue;
  for (int k = 0; k < 50; ++k)
    queue.push({k, Eigen::Isometry3d::Identity(), {}}, [] {
      ADD_FAILURE() << "a push without a capacity waited";
      return false;
    });
  EXPECT_EQ(queue.depth(), 50U);
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
