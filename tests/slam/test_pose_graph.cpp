#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "adit/slam/correction_track.hpp"
#include "adit/slam/pose_graph.hpp"
#include "adit/slam/pose_graph_solver.hpp"

namespace adit::slam {
namespace {

Eigen::Isometry3d pose(double x, double y, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << x, y, 0.0;
  return T;
}

// A 20 m square driven once, one node per metre (80 nodes, back at the start),
// the odometry turning 0.1° too far per metre.
struct Square {
  std::vector<Eigen::Isometry3d> truth;
  PoseGraph graph;
};

Square drifted_square() {
  Square s;
  for (int k = 0; k <= 80; ++k) {
    const int side = std::min(k / 20, 3);
    const double along = k - 20 * side;
    const double yaw = side * M_PI / 2;
    const Eigen::Vector2d corners[4] = {{0, 0}, {20, 0}, {20, 20}, {0, 20}};
    const Eigen::Vector2d p = corners[side] + along * Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
    s.truth.push_back(pose(p.x(), p.y(), k == 80 ? 2 * M_PI : yaw));
  }
  const Eigen::Isometry3d bias = pose(0, 0, 0.1 * M_PI / 180);
  s.graph.nodes.push_back(s.truth[0]);
  for (int k = 1; k <= 80; ++k) {
    const Eigen::Isometry3d motion = s.truth[k - 1].inverse() * s.truth[k];
    s.graph.edges.push_back({static_cast<std::size_t>(k - 1), static_cast<std::size_t>(k), motion * bias,
                             odometry_information(motion), EdgeKind::odometry});
    s.graph.nodes.push_back(s.graph.nodes.back() * motion * bias);
  }
  return s;
}

double end_error(const Square& s) { return (s.graph.nodes.back().translation() - s.truth.back().translation()).norm(); }

Matrix6d loop_information() {
  Vector6d d;
  d << Eigen::Vector3d::Constant(1 / (0.05 * 0.05)), Eigen::Vector3d::Constant(1 / (0.005 * 0.005));
  return d.asDiagonal();
}

TEST(PoseGraph, ALoopEdgeClosesTheSquare) {
  Square s = drifted_square();
  const double before = end_error(s);
  s.graph.edges.push_back({0, 80, Eigen::Isometry3d::Identity(), loop_information(), EdgeKind::loop});
  const PoseGraphSolution solution = optimize(s.graph);
  EXPECT_TRUE(solution.converged);
  EXPECT_LT(solution.final_cost, solution.initial_cost);
  EXPECT_GT(before, 1.0);
  EXPECT_LT(end_error(s), 0.05);
  double worst = 0.0;
  for (std::size_t k = 0; k < s.truth.size(); ++k)
    worst = std::max(worst, (s.graph.nodes[k].translation() - s.truth[k].translation()).norm());
  EXPECT_LT(worst, 0.3 * before);  // the correction spreads along the loop
  EXPECT_TRUE(s.graph.nodes[0].isApprox(s.truth[0], 1e-12));  // node 0 holds the frame
}

// Among right loops, one that says the end lies 8 m off: the Cauchy kernel
// keeps the graph with the right ones and leaves the wrong one's residual large.
TEST(PoseGraph, TheRobustKernelOutvotesAWrongLoop) {
  Square s = drifted_square();
  for (int k : {0, 1, 2, 3})
    s.graph.edges.push_back({static_cast<std::size_t>(k), static_cast<std::size_t>(80 - k),
                             s.truth[k].inverse() * s.truth[80 - k], loop_information(), EdgeKind::loop});
  s.graph.edges.push_back({10, 80, s.truth[10].inverse() * s.truth[80] * pose(8.0, 0.0, 0.0), loop_information(),
                           EdgeKind::loop});
  const PoseGraphSolution solution = optimize(s.graph);
  EXPECT_LT(end_error(s), 0.1);
  ASSERT_EQ(solution.loop_residuals.size(), 5U);
  for (int i = 0; i < 4; ++i) EXPECT_LT(solution.loop_residuals[i], 3.0);
  EXPECT_GT(solution.loop_residuals[4], 50.0);
}

// Odometry that tilts 0.05° per metre: the gravity prior keeps roll and pitch.
TEST(PoseGraph, GravityHoldsRollAndPitch) {
  PoseGraph graph;
  graph.nodes.push_back(Eigen::Isometry3d::Identity());
  Eigen::Isometry3d tilt = Eigen::Isometry3d::Identity();
  tilt.linear() = Eigen::AngleAxisd(0.05 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  for (std::size_t k = 1; k <= 40; ++k) {
    const Eigen::Isometry3d motion = pose(1.0, 0.0, 0.0) * tilt;
    graph.edges.push_back({k - 1, k, motion, odometry_information(motion), EdgeKind::odometry});
    graph.nodes.push_back(graph.nodes.back() * motion);
    graph.gravity.push_back({k, Eigen::Vector3d::UnitZ(), 1.0 / (0.001 * 0.001)});
  }
  const double before = std::acos((graph.nodes.back().linear() * Eigen::Vector3d::UnitZ()).z());
  optimize(graph);
  const double after = std::acos(std::min(1.0, (graph.nodes.back().linear() * Eigen::Vector3d::UnitZ()).z()));
  EXPECT_GT(before, 1.5 * M_PI / 180);
  EXPECT_LT(after, 0.2 * M_PI / 180);
}

// A flat 75 m square driven at 1 m/s (a keyframe a metre) whose odometry
// pitches up as an accelerometer's bias walks, 0 → 10 mrad over the 300 s
// (mine:robot:300:5's went to 12 mrad), so the route climbs 1 cm a metre by
// the end; each keyframe's up as its map pose holds it; one loop at the
// start. Ups held as measured: the graph cannot re-level the route and
// spreads the height gap as translation. With the tilt walk it re-levels the
// route and reads the tilt back.
TEST(PoseGraph, TheTiltWalkLevelsARouteClimbingWithTheAccelerometersBias) {
  constexpr int kSide = 75;
  constexpr int kNodes = 4 * kSide;
  std::vector<Eigen::Isometry3d> truth;
  for (int k = 0; k <= kNodes; ++k) {
    const int side = std::min(k / kSide, 3);
    const double along = k - kSide * side;
    const double yaw = side * M_PI / 2;
    const Eigen::Vector2d corners[4] = {{0, 0}, {kSide, 0}, {kSide, kSide}, {0, kSide}};
    const Eigen::Vector2d p = corners[side] + along * Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
    truth.push_back(pose(p.x(), p.y(), k == kNodes ? 2 * M_PI : yaw));
  }
  const auto run = [&truth](double walk) {
    PoseGraph graph;
    std::vector<Eigen::Isometry3d> odometry;
    double z = 0.0;
    for (std::size_t k = 0; k <= kNodes; ++k) {
      const double beta = 0.010 * static_cast<double>(k) / kNodes;  // nose up, rad
      if (k > 0) z += beta * 1.0;                                     // 1 m a keyframe
      Eigen::Isometry3d o = truth[k];
      o.translation().z() = z;
      o.linear() = o.linear() * Eigen::AngleAxisd(-beta, Eigen::Vector3d::UnitY()).toRotationMatrix();
      odometry.push_back(o);
    }
    graph.nodes.push_back(odometry[0]);
    for (std::size_t k = 1; k <= kNodes; ++k) {
      const Eigen::Isometry3d motion = odometry[k - 1].inverse() * odometry[k];
      graph.edges.push_back({k - 1, k, motion, odometry_information(motion), EdgeKind::odometry});
      graph.nodes.push_back(graph.nodes.back() * motion);
    }
    for (std::size_t k = 0; k <= kNodes; ++k)
      graph.gravity.push_back({k, odometry[k].linear().transpose() * Eigen::Vector3d::UnitZ(), 1.0 / (0.002 * 0.002),
                               static_cast<double>(k)});
    graph.tilt_walk_rad_per_sqrt_s = walk;
    graph.edges.push_back({0, kNodes, Eigen::Isometry3d::Identity(), loop_information(), EdgeKind::loop});
    optimize(graph);
    double worst_z = 0.0;
    for (const Eigen::Isometry3d& n : graph.nodes) worst_z = std::max(worst_z, std::abs(n.translation().z()));
    const double tilt = graph.tilt_offsets.empty() ? 0.0 : graph.tilt_offsets.back().norm();
    return std::pair{worst_z, tilt};
  };
  const auto [held_z, held_tilt] = run(0.0);
  const auto [walk_z, walk_tilt] = run(3.0e-3 / 9.80665);  // the config's default accelerometer bias walk
  EXPECT_GT(held_z, 0.2);           // of the 1.5 m climbed by the end, a quarter stays amid the route
  EXPECT_EQ(held_tilt, 0.0);
  EXPECT_LT(walk_z, 0.5 * held_z);  // re-levelled
  EXPECT_GT(walk_tilt, 0.005);      // the tilt read back: 10 mrad at the end
  EXPECT_LT(walk_tilt, 0.015);
}

// A corridor driven out and back, one node a metre: the first five nodes
// were mapped before the odometry was anchored to a prior map, 4 cm off in
// y in the prior's frame; from node 5 on the odometry holds to the prior
// (the truth). Loops on the way back measure the true relative poses to the
// first nodes. Held by absolute edges, the anchored nodes stay and the loops
// bring the first nodes towards them; holding node 0 instead carries its
// 4 cm onto every node the loops reach.
struct AnchoredCorridor {
  std::vector<Eigen::Isometry3d> truth;
  PoseGraph graph;
};

AnchoredCorridor anchored_corridor(bool absolute) {
  AnchoredCorridor c;
  for (int k = 0; k <= 20; ++k) c.truth.push_back(pose(k, 0, 0));
  for (int k = 20; k >= 0; --k) c.truth.push_back(pose(k, 0.5, M_PI));
  const Eigen::Isometry3d off = pose(0, 0.04, 0);
  std::vector<Eigen::Isometry3d> odometry;
  for (std::size_t k = 0; k < c.truth.size(); ++k) odometry.push_back(k < 5 ? off * c.truth[k] : c.truth[k]);
  c.graph.nodes = odometry;
  for (std::size_t k = 1; k < odometry.size(); ++k) {
    const Eigen::Isometry3d motion = odometry[k - 1].inverse() * odometry[k];
    c.graph.edges.push_back({k - 1, k, motion, odometry_information(motion), EdgeKind::odometry});
  }
  const std::size_t last = c.truth.size() - 1;
  for (std::size_t k = 0; k < 5; ++k)  // node last - k passes node k on the way back
    c.graph.edges.push_back({k, last - k, c.truth[k].inverse() * c.truth[last - k], loop_information(), EdgeKind::loop});
  if (absolute) {
    Vector6d d;
    d << Eigen::Vector3d::Constant(1 / (0.02 * 0.02)), Eigen::Vector3d::Constant(1 / (0.0035 * 0.0035));
    for (std::size_t k = 5; k <= last; ++k) c.graph.absolute.push_back({k, odometry[k], d.asDiagonal()});
  }
  return c;
}

double worst_error(const AnchoredCorridor& c, std::size_t from, std::size_t to) {
  double worst = 0.0;
  for (std::size_t k = from; k < to; ++k)
    worst = std::max(worst, (c.graph.nodes[k].translation() - c.truth[k].translation()).norm());
  return worst;
}

TEST(PoseGraph, AbsoluteEdgesHoldTheAnchoredNodesAndTheLoopsMoveTheOthersTowardsThem) {
  AnchoredCorridor held = anchored_corridor(true);
  EXPECT_TRUE(optimize(held.graph).converged);
  EXPECT_LT(worst_error(held, 5, held.truth.size()), 0.01);  // the anchored nodes stay on the prior
  // The first ones come towards them, as far as the odometry edges into the
  // anchor (which hold the 4 cm) let loops of 5 cm σ move them.
  EXPECT_LT(worst_error(held, 0, 5), 0.03);
  AnchoredCorridor fixed_first = anchored_corridor(false);
  EXPECT_TRUE(optimize(fixed_first.graph).converged);
  EXPECT_TRUE(fixed_first.graph.nodes[0].isApprox(anchored_corridor(false).graph.nodes[0], 1e-12));
  EXPECT_GT(worst_error(fixed_first, 30, fixed_first.truth.size()), 0.03);  // the first node's 4 cm, carried back
}

TEST(PoseGraph, OdometryInformationLoosensWithDistance) {
  const Matrix6d near = odometry_information(pose(0.1, 0, 0));
  const Matrix6d far = odometry_information(pose(5.0, 0, 0));
  EXPECT_GT(near(0, 0), far(0, 0));
  EXPECT_GT(near(5, 5), far(5, 5));
}

}  // namespace
}  // namespace adit::slam

namespace adit::slam {
namespace {

TEST(CorrectionTrack, InterpolatesBetweenKeyframesAndHoldsBeyond) {
  const std::vector<std::int64_t> stamps{100, 200};
  const std::vector<Eigen::Isometry3d> odometry{pose(0, 0, 0), pose(1, 0, 0)};
  const std::vector<Eigen::Isometry3d> graph{pose(0, 0, 0), pose(1, 0.2, 0.1)};
  const CorrectionTrack track(stamps, graph, odometry);
  EXPECT_TRUE(track.at(50).isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  const Eigen::Isometry3d end = graph[1] * odometry[1].inverse();
  EXPECT_TRUE(track.at(200).isApprox(end, 1e-12));
  EXPECT_TRUE(track.at(999).isApprox(end, 1e-12));
  const Eigen::Isometry3d mid = track.at(150);
  EXPECT_NEAR(Eigen::AngleAxisd(mid.linear()).angle(), 0.05, 1e-9);  // half the turn
  EXPECT_NEAR(track.max_rotation_rad(), 0.1, 1e-9);
}

// The odometry's poses P differ from those the map was built at, M (the
// map's refinement moved them): retargeted, the track takes each P(t) to
// C(t)·M(t), where the graph put the map's pose, between and beyond the keyframes.
TEST(CorrectionTrack, RetargetedTakesOtherPosesWhereTheGraphPutTheMapsPose) {
  const std::vector<std::int64_t> keyframes{1'000'000'000, 3'000'000'000};
  const std::vector<Eigen::Isometry3d> map_keyframes{pose(0, 0, 0), pose(20, 0, 0.1)};
  const CorrectionTrack track(keyframes, std::vector{pose(0, 0, 0), pose(20, 0.4, 0.12)}, map_keyframes);
  Trajectory built_at;
  Trajectory odometry;
  for (int i = 0; i <= 8; ++i) {  // 0.5 s apart from 0.5 s to 4.5 s: before, between and beyond the keyframes
    const double t = 0.5 * (i + 1);
    built_at.push_back(t, pose(10.0 * (t - 1.0), 0.0, 0.05 * (t - 1.0)));
    Eigen::Isometry3d p = built_at.poses.back();
    p.translation().z() += 0.1 * t;  // the odometry climbed where the map did not
    odometry.push_back(t, p);
  }
  const CorrectionTrack moved = retargeted(track, built_at, odometry);
  for (std::size_t i = 0; i < odometry.size(); ++i) {
    const auto ns = static_cast<std::int64_t>(std::llround(odometry.stamps[i] * 1e9));
    const Eigen::Isometry3d want = track.at(ns) * built_at.poses[i];
    EXPECT_TRUE((moved.at(ns) * odometry.poses[i]).isApprox(want, 1e-9)) << i;
    EXPECT_GT(((track.at(ns) * odometry.poses[i]).translation() - want.translation()).norm(), 0.04) << i;
  }
  EXPECT_TRUE(retargeted(track, Trajectory{}, odometry).empty());
  EXPECT_TRUE(retargeted(CorrectionTrack{}, built_at, odometry).empty());
}

// The live tiles follow the graph: a sample moves by the correction at its
// scan's time; a tile is sent again when a new correction moves any of its
// samples by more than the threshold.
TEST(CorrectionTrack, MovesEachSampleByItsScansCorrectionAndSaysWhenATileMoved) {
  const std::vector<std::int64_t> stamps{1'000'000'000, 2'000'000'000};  // 1 s, 2 s
  const std::vector<Eigen::Isometry3d> odometry{pose(0, 0, 0), pose(10, 0, 0)};
  const CorrectionTrack first(stamps, std::vector{pose(0, 0, 0), pose(10, 0.5, 0)}, odometry);
  const CorrectionTrack second(stamps, std::vector{pose(0, 0, 0), pose(10, 0.6, 0)}, odometry);
  const std::vector<MapSample> early{{Eigen::Vector3f(1, 2, 0), 5.0F, 0.5}, {Eigen::Vector3f(3, 2, 0), 6.0F, 1.0}};
  const std::vector<MapSample> late{{Eigen::Vector3f(12, 2, 0), 5.0F, 2.0}, {Eigen::Vector3f(13, 2, 0), 5.0F, 2.0},
                                    {Eigen::Vector3f(14, 1, 1), 5.0F, 3.5}};
  std::vector<MapSample> out;
  correct_samples(late, &first, Eigen::Isometry3d::Identity(), out);
  ASSERT_EQ(out.size(), late.size());
  for (std::size_t i = 0; i < late.size(); ++i) {
    const Eigen::Vector3d want = first.at(static_cast<std::int64_t>(late[i].time_s * 1e9)) * late[i].position.cast<double>();
    EXPECT_LT((out[i].position.cast<double>() - want).norm(), 1e-5);
    EXPECT_EQ(out[i].intensity, late[i].intensity);
    EXPECT_EQ(out[i].time_s, late[i].time_s);
  }
  EXPECT_NEAR((out[2].position - late[2].position).norm(), 0.5F, 1e-5F);  // held beyond the last keyframe
  correct_samples(early, &first, pose(5, 0, 0), out);            // then placed
  EXPECT_LT((out[0].position - Eigen::Vector3f(6, 2, 0)).norm(), 1e-5F);

  // The start is not corrected; the end moves 0.5 m by the first correction and 0.1 m further by the second.
  EXPECT_FALSE(correction_moves(early, nullptr, &first, 0.02));
  EXPECT_TRUE(correction_moves(late, nullptr, &first, 0.02));
  EXPECT_TRUE(correction_moves(late, &first, &second, 0.02));
  EXPECT_FALSE(correction_moves(late, &first, &second, 0.2));
  EXPECT_FALSE(correction_moves(late, &first, &first, 0.0));
}

// A live tile remembers the correction it was sent with only at its samples'
// times: the slice gives the same bits there and holds the keyframes that
// bracket them, not the session's.
TEST(CorrectionTrack, ASliceGivesTheSameCorrectionAtItsSamplesTimes) {
  std::vector<std::int64_t> stamps;
  std::vector<Eigen::Isometry3d> odometry, graph;
  for (int k = 0; k < 1000; ++k) {
    stamps.push_back(std::int64_t{k} * 1'000'000'000 + 500'000'000);  // 0.5 s, 1.5 s, ...
    odometry.push_back(pose(k, 0, 0));
    graph.push_back(pose(k, 0.001 * k * k, 1e-4 * k));
  }
  const CorrectionTrack track(stamps, graph, odometry);
  // Samples at 0.1 s (before the first keyframe), amid 300-302 s and 700 s, at
  // a keyframe's own stamp (800.5 s) and at 2000 s (after the last).
  std::vector<MapSample> samples;
  for (double t : {0.1, 300.2, 300.2, 301.7, 302.0, 700.9, 800.5, 2000.0})
    samples.push_back({Eigen::Vector3f(1, 2, 3), 1.0F, t});
  const CorrectionTrack slice = track.slice_for(samples);
  EXPECT_LE(slice.stamps_ns().size(), 12U);
  for (const MapSample& s : samples) {
    const auto t = static_cast<std::int64_t>(std::llround(s.time_s * 1e9));
    EXPECT_TRUE(slice.at(t).matrix() == track.at(t).matrix()) << s.time_s;
  }
  EXPECT_FALSE(correction_moves(samples, &slice, &track, 0.0));
  EXPECT_TRUE(CorrectionTrack().slice_for(samples).empty());
}

}  // namespace
}  // namespace adit::slam

namespace adit::slam {
namespace {

// A live tile sent in parts keeps one slice for all of them: two slices
// merged give the track's own bits at the times of both parts.
TEST(CorrectionTrack, TwoSlicesMergedAreTheTrackAtBothSetsOfTimes) {
  std::vector<std::int64_t> stamps;
  std::vector<Eigen::Isometry3d> graph, odometry;
  for (int k = 0; k < 40; ++k) {
    stamps.push_back(std::int64_t{k} * 100'000'000'000 / 4);  // every 25 s
    Eigen::Isometry3d g = Eigen::Isometry3d::Identity();
    g.translation() = Eigen::Vector3d(0.01 * k * k, 0.02 * k, -0.003 * k);
    g.linear() = Eigen::AngleAxisd(0.002 * k, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    graph.push_back(g);
    odometry.push_back(Eigen::Isometry3d::Identity());
  }
  const CorrectionTrack track(stamps, graph, odometry);
  const auto samples_at = [](std::initializer_list<double> times) {
    std::vector<MapSample> out;
    for (double t : times) out.push_back({Eigen::Vector3f(1, 2, 3), 1.0F, t});
    return out;
  };
  // Overlapping, adjacent and far apart; one at a keyframe's own stamp, one past the end.
  const std::vector<MapSample> a = samples_at({10.0, 30.0, 31.0, 300.0, 975.0});
  const std::vector<MapSample> b = samples_at({31.5, 49.0, 50.0, 640.0, 2000.0});
  const CorrectionTrack merged = track.slice_for(a).merged_with(track.slice_for(b));
  for (const std::vector<MapSample>* part : {&a, &b}) {
    for (const MapSample& s : *part) {
      const auto t = static_cast<std::int64_t>(std::llround(s.time_s * 1e9));
      EXPECT_TRUE(merged.at(t).matrix() == track.at(t).matrix()) << s.time_s;
    }
  }
  EXPECT_LT(merged.stamps_ns().size(), stamps.size());
  EXPECT_TRUE(std::is_sorted(merged.stamps_ns().begin(), merged.stamps_ns().end()));
  EXPECT_EQ(std::adjacent_find(merged.stamps_ns().begin(), merged.stamps_ns().end()), merged.stamps_ns().end());
  EXPECT_TRUE(CorrectionTrack().merged_with(track.slice_for(a)).stamps_ns() == track.slice_for(a).stamps_ns());
}

}  // namespace
}  // namespace adit::slam

namespace adit::slam {
namespace {

Eigen::Isometry3d small_motion(std::mt19937& rng, double metres, double radians) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.translation() = metres * Eigen::Vector3d(n(rng), n(rng), n(rng));
  m.linear() = Eigen::AngleAxisd(radians * n(rng), Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized())
                   .toRotationMatrix();
  return m;
}

// The corner gate never says "unmoved" where a sample in the box moves more
// than the threshold (it would leave a live tile misplaced), and it does
// say it for small corrections (else it would save nothing).
TEST(CorrectionTrack, TheCornerGateNeverMissesAMovedSampleAndPassesSmallCorrections) {
  std::mt19937 rng(11);
  const Eigen::AlignedBox3d box(Eigen::Vector3d(20, -40, 0), Eigen::Vector3d(40, -20, 20));
  std::uniform_real_distribution<double> inside(0.0, 1.0);
  int moved = 0, gated = 0;
  for (int trial = 0; trial < 300; ++trial) {
    // An old track of 20 keyframes a second apart; the new one has 5 more and
    // moves the old ones by up to a few cm (scale varies by trial).
    const double scale = 0.002 * (trial % 10);
    std::vector<std::int64_t> stamps;
    std::vector<Eigen::Isometry3d> old_graph, new_graph, odometry;
    for (int k = 0; k < 25; ++k) {
      stamps.push_back(std::int64_t{k} * 1'000'000'000 + 500'000'000);
      const Eigen::Isometry3d g = small_motion(rng, 0.5, 0.01);
      if (k < 20) old_graph.push_back(g);
      new_graph.push_back(g * small_motion(rng, scale, scale / 30.0));
      odometry.push_back(Eigen::Isometry3d::Identity());
    }
    const std::vector<std::int64_t> old_stamps(stamps.begin(), stamps.begin() + 20);
    const CorrectionTrack old_track(old_stamps, old_graph, std::vector(odometry.begin(), odometry.begin() + 20));
    const CorrectionTrack new_track(stamps, new_graph, odometry);
    std::vector<MapSample> samples;
    const double newest = 22.0 * inside(rng);
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector3d u(inside(rng), inside(rng), inside(rng));
      const Eigen::Vector3d p = box.min() + u.cwiseProduct(box.sizes());
      samples.push_back({p.cast<float>(), 1.0F, newest * inside(rng)});
    }
    samples.push_back({box.max().cast<float>(), 1.0F, newest});
    const CorrectionTrack slice = old_track.slice_for(samples);
    const bool moves = correction_moves(samples, &slice, &new_track, 0.02);
    const bool may = correction_may_move(slice, &new_track, box, newest, 0.02);
    if (moves) {
      ++moved;
      EXPECT_TRUE(may) << "trial " << trial;
    }
    if (!may) ++gated;
  }
  EXPECT_GT(moved, 30);
  EXPECT_GT(gated, 30);
  EXPECT_TRUE(correction_may_move(CorrectionTrack(), nullptr, box, 1.0, 0.02)) << "an empty slice tells nothing";
}

}  // namespace
}  // namespace adit::slam
