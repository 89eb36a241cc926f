#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <tuple>

#include "adit/slam/loop_closer.hpp"
#include "loop_scenes.hpp"
#include "synthetic_scenes.hpp"

namespace adit::slam {
namespace {

using test::pose_at;

struct Drive {
  std::vector<Eigen::Isometry3d> truth;
  std::vector<Eigen::Isometry3d> odometry;  // 1 % long and turning 0.05° per metre too far
};

Drive drive(const std::function<Eigen::Isometry3d(double)>& path, double length_m, double step_m) {
  Drive d;
  for (double s = 0.0; s <= length_m + 1e-9; s += step_m) d.truth.push_back(path(s));
  d.odometry.push_back(d.truth.front());
  for (std::size_t k = 1; k < d.truth.size(); ++k) {
    const Eigen::Isometry3d motion = d.truth[k - 1].inverse() * d.truth[k];
    const Eigen::Isometry3d bias = pose_at(0.01 * motion.translation().norm(), 0.0, 0.05 * M_PI / 180 * step_m);
    d.odometry.push_back(d.odometry.back() * motion * bias);
  }
  return d;
}

struct Outcome {
  double error_before = 0.0;  // worst keyframe position error of the odometry
  double error_after = 0.0;   // of the graph
  double end_before = 0.0;    // the last keyframe's
  double end_after = 0.0;
  double worst_loop_error_m = 0.0;  // of the accepted loops' measurements against the truth
  LoopClosureStats stats;
};

Outcome close_loops(const std::vector<Eigen::Vector3f>& world, const Drive& d) {
  LoopCloser closer;
  for (std::size_t k = 0; k < d.truth.size(); ++k)
    closer.add_keyframe(static_cast<std::int64_t>(k) * 1'000'000'000, d.odometry[k],
                        test::scan_of(world, d.truth[k], 1000 + static_cast<unsigned>(k)));
  Outcome o;
  o.stats = closer.stats();
  // Every verified loop is accepted, refused by the guard or still waiting: none is lost.
  EXPECT_EQ(o.stats.verified, o.stats.accepted + o.stats.rejected_inconsistent + closer.unconfirmed());
  for (std::size_t k = 0; k < d.truth.size(); ++k) {
    o.error_before = std::max(o.error_before, (d.odometry[k].translation() - d.truth[k].translation()).norm());
    o.error_after = std::max(o.error_after, (closer.poses()[k].translation() - d.truth[k].translation()).norm());
  }
  o.end_before = (d.odometry.back().translation() - d.truth.back().translation()).norm();
  o.end_after = (closer.poses().back().translation() - d.truth.back().translation()).norm();
  for (const PoseGraphEdge& e : closer.graph().edges) {
    if (e.kind != EdgeKind::loop) continue;
    const Eigen::Isometry3d truth = d.truth[e.from].inverse() * d.truth[e.to];
    o.worst_loop_error_m = std::max(o.worst_loop_error_m, (truth.inverse() * e.measurement).translation().norm());
  }
  return o;
}

constexpr float kSide = 24.0F;

const std::vector<Eigen::Vector3f>& ring_world() {
  static const std::vector<Eigen::Vector3f> world = test::ring_corridor(kSide, 36, 17);
  return world;
}

// 1.3 laps of a 96 m ring: the second pass closes loops, all true, and the
// graph pulls the keyframes back.
TEST(LoopCloser, ClosesARingDrivenTwice) {
  const Drive d = drive([](double s) { return test::ring_pose(kSide, s); }, 1.3 * 4 * kSide, 2.0);
  const Outcome o = close_loops(ring_world(), d);
  EXPECT_GE(o.stats.accepted, 5U);
  EXPECT_LT(o.worst_loop_error_m, 0.1);
  EXPECT_GT(o.end_before, 1.0);
  EXPECT_LT(o.end_after, 0.3 * o.end_before);
  EXPECT_LT(o.error_after, o.error_before);
  EXPECT_GE(o.stats.optimizations, 1U);
  EXPECT_GT(o.stats.optimization_s_total, 0.0);
  EXPECT_GE(o.stats.optimization_s_total, o.stats.last_optimization_s) << "the sum of every optimisation's time";
}

// Loops found within optimize_every_s of the last optimisation wait for the
// first keyframe that long after it, and are solved together; the first loop
// is solved at once, and refine() solves what still waits. The ring's second
// lap closes a loop at nearly every keyframe (1 s apart): the coalesced graph
// is solved a few times, closes nearly the same loops and ends where the
// graph solved at every loop ends.
TEST(LoopCloser, LoopsFoundSoonAfterAnOptimisationWaitForTheNextAndEndTheSame) {
  const Drive d = drive([](double s) { return test::ring_pose(kSide, s); }, 1.3 * 4 * kSide, 2.0);
  const auto run = [&d](double every_s, LoopCloser& closer) {
    std::vector<std::int64_t> solved_at;  // keyframe stamps where add_keyframe optimised
    for (std::size_t k = 0; k < d.truth.size(); ++k) {
      const std::int64_t stamp = static_cast<std::int64_t>(k) * 1'000'000'000;
      const std::size_t accepted_before = closer.stats().accepted;
      const bool optimised =
          closer.add_keyframe(stamp, d.odometry[k], test::scan_of(ring_world(), d.truth[k], 1000 + static_cast<unsigned>(k)));
      if (optimised) {
        EXPECT_EQ(closer.unsolved(), 0U);
        if (!solved_at.empty()) {
          EXPECT_GE(stamp - solved_at.back(), static_cast<std::int64_t>(every_s * 1e9));
        }
        solved_at.push_back(stamp);
      } else if (closer.unsolved() > 0) {  // loops wait only within every_s of the last solve
        EXPECT_FALSE(solved_at.empty()) << "loops wait before any solve";
        if (!solved_at.empty()) {
          EXPECT_LT(stamp - solved_at.back(), static_cast<std::int64_t>(every_s * 1e9));
        }
      }
      if (closer.stats().accepted > 0 && accepted_before == 0) {
        EXPECT_TRUE(optimised) << "the first loop waits for nothing";
      }
    }
    return solved_at;
  };
  LoopClosureConfig every_loop, coalesced;
  coalesced.optimize_every_s = 5.0;
  LoopCloser at_once(every_loop), batched(coalesced);
  const std::vector<std::int64_t> at_once_solves = run(0.0, at_once);
  const std::vector<std::int64_t> batched_solves = run(5.0, batched);
  ASSERT_GE(at_once.stats().accepted, 5U);
  // The same candidates; those whose overlap lies at the threshold (0.59-0.60
  // of 0.6) fall either way from a graph a few keyframes older.
  EXPECT_EQ(batched.stats().candidates, at_once.stats().candidates);
  EXPECT_GE(batched.stats().accepted, at_once.stats().accepted * 9 / 10) << "of " << at_once.stats().accepted;
  EXPECT_LT(batched_solves.size(), at_once_solves.size() / 2) << at_once_solves.size() << " solves at every loop";
  const std::size_t waiting = batched.unsolved();
  batched.refine();
  at_once.refine();
  EXPECT_EQ(batched.unsolved(), 0U) << waiting << " loops waited for the session's end";
  double worst_m = 0.0;
  for (std::size_t k = 0; k < d.truth.size(); ++k)
    worst_m = std::max(worst_m, (batched.poses()[k].translation() - at_once.poses()[k].translation()).norm());
  EXPECT_LT(worst_m, 0.01) << "the two graphs end apart";
}

// The same drive with all but the newest 5 keyframe scans on disk closes the
// same loops; the scans of the first lap damaged on disk before the second:
// each such candidate is refused as unreadable, none reaches the graph, the
// closer goes on.
TEST(LoopCloser, ScansOnDiskCloseTheSameLoopsAndDamagedOnesAreRefused) {
  const Drive d = drive([](double s) { return test::ring_pose(kSide, s); }, 1.3 * 4 * kSide, 2.0);
  const auto run = [&d](bool damage) {
    const std::filesystem::path folder = std::filesystem::temp_directory_path() / "adit_test_loop_closer_scans";
    std::filesystem::remove_all(folder);
    LoopClosureConfig config;
    config.scans_in_ram = 5;
    LoopCloser closer(config);
    closer.spill_scans_to(folder);
    for (std::size_t k = 0; k < d.truth.size(); ++k) {
      if (damage && k == 48)  // the first lap done: every scan on disk gets a flipped byte
        for (std::size_t j = 0; j < closer.scans().spilled(); ++j) {
          std::fstream f(closer.scans().file_of(j), std::ios::in | std::ios::out | std::ios::binary);
          f.seekp(40);
          f.put('\x7f');
        }
      closer.add_keyframe(static_cast<std::int64_t>(k) * 1'000'000'000, d.odometry[k],
                          test::scan_of(ring_world(), d.truth[k], 1000 + static_cast<unsigned>(k)));
    }
    std::filesystem::remove_all(folder);
    return std::pair{closer.stats(), closer.events()};
  };
  const Outcome in_ram = close_loops(ring_world(), d);
  const auto [on_disk, events] = run(false);
  EXPECT_EQ(on_disk.accepted, in_ram.stats.accepted);
  EXPECT_EQ(on_disk.candidates, in_ram.stats.candidates);
  EXPECT_EQ(on_disk.rejected_unreadable, 0U);
  const auto [damaged, damaged_events] = run(true);
  EXPECT_GT(damaged.rejected_unreadable, 0U);
  EXPECT_LT(damaged.accepted, in_ram.stats.accepted);
  EXPECT_TRUE(std::any_of(damaged_events.begin(), damaged_events.end(),
                          [](const LoopEvent& e) { return e.outcome == "keyframe_unreadable"; }));
}

// A long session keeps the first config.events_kept events whole and counts
// every candidate's outcome.
TEST(LoopCloser, KeepsTheFirstEventsAndCountsEveryOutcome) {
  const Drive d = drive([](double s) { return test::ring_pose(kSide, s); }, 1.3 * 4 * kSide, 2.0);
  const auto run = [&d](std::size_t kept) {
    LoopClosureConfig config;
    config.events_kept = kept;
    LoopCloser closer(config);
    for (std::size_t k = 0; k < d.truth.size(); ++k)
      closer.add_keyframe(static_cast<std::int64_t>(k) * 1'000'000'000, d.odometry[k],
                          test::scan_of(ring_world(), d.truth[k], 1000 + static_cast<unsigned>(k)));
    return std::tuple{closer.stats(), closer.events(), closer.outcomes()};
  };
  const auto [all_stats, all_events, all_outcomes] = run(1000);
  const auto [stats, events, outcomes] = run(3);
  ASSERT_GT(all_events.size(), 3U);
  EXPECT_EQ(all_events.size(), all_stats.candidates);  // one event a candidate
  ASSERT_EQ(events.size(), 3U);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(events[i].candidate, all_events[i].candidate);
  EXPECT_EQ(outcomes, all_outcomes);
  std::size_t counted = 0;
  for (const auto& [outcome, count] : outcomes) counted += count;
  EXPECT_EQ(counted, stats.candidates);
  EXPECT_EQ(outcomes.at("accepted"), static_cast<std::size_t>(std::count_if(
                                         all_events.begin(), all_events.end(),
                                         [](const LoopEvent& e) { return e.outcome == "accepted"; })));
}

// Out 40 m along the ring and back the other way: revisits in reverse,
// found at a half turn of the descriptor and closed.
TEST(LoopCloser, ClosesAReverseRevisit) {
  const auto path = [](double s) {
    return s <= 40.0 ? test::ring_pose(kSide, s) : test::ring_pose(kSide, 80.0 - s) * pose_at(0, 0, M_PI);
  };
  const Drive d = drive(path, 80.0, 2.0);
  const Outcome o = close_loops(ring_world(), d);
  EXPECT_GE(o.stats.accepted, 3U);
  EXPECT_LT(o.worst_loop_error_m, 0.1);
  EXPECT_LT(o.end_after, 0.5 * o.end_before);
}

// Out and back along a plain straight tunnel: every revisit looks right and
// none can be measured along the axis. Loops get in only as partial ones
// (across the tunnel and in attitude; on the way back the reading turned half
// round is set aside by the graph's heading), so no wrong information reaches
// the map: along the axis no keyframe ends farther from the truth than the
// odometry put it (the loops' attitude may move it a little, towards the truth).
TEST(LoopCloser, AlongAPlainSymmetricTunnelNoLoopMovesTheAxis) {
  const std::vector<Eigen::Vector3f> tunnel = test::tunnel(150'000, 9, 200.0F);
  const auto path = [](double s) { return s <= 40.0 ? pose_at(s - 20.0, 0, 0) : pose_at(60.0 - s, 0, M_PI); };
  const Drive d = drive(path, 80.0, 2.0);
  LoopCloser closer;
  for (std::size_t k = 0; k < d.truth.size(); ++k)
    closer.add_keyframe(static_cast<std::int64_t>(k), d.odometry[k], test::scan_of(tunnel, d.truth[k], 2000 + k));
  EXPECT_GT(closer.stats().candidates, 0U);  // the descriptor does see revisits
  EXPECT_GT(closer.stats().accepted, 0U);                       // and some got in
  EXPECT_EQ(closer.stats().verified, closer.stats().partial);  // only partial ones pass
  for (std::size_t k = 0; k < d.truth.size(); ++k) {
    const double graph_error = std::abs(closer.poses()[k].translation().x() - d.truth[k].translation().x());
    const double odometry_error = std::abs(d.odometry[k].translation().x() - d.truth[k].translation().x());
    EXPECT_LE(graph_error, odometry_error + 0.01) << k;
    EXPECT_NEAR(closer.poses()[k].translation().x(), d.odometry[k].translation().x(), 0.06) << k;
  }
  EXPECT_GT(closer.stats().set_aside_readings, 0U);  // the half-turned readings on the way back
}

}  // namespace
}  // namespace adit::slam
