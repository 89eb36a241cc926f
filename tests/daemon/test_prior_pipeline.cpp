// aditd's sessions with a prior map (prior_map.dir) on a simulated building
// drive replayed at its own pace: thread "prior" localises the odometry's
// first scans, the odometry anchors to the prior, the anchor is written to the
// session's prior_frame.json, and the session's exports are in the prior's
// frame: the trajectory follows the truth in it (the world's) from then on,
// and the map lies on the prior.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "adit/daemon/pipeline.hpp"
#include "adit/daemon/prior_localiser.hpp"
#include "adit/daemon/session_frame.hpp"
#include "adit/daemon/sessions.hpp"
#include "adit/protocol/map_import.hpp"
#include "adit/slam/prior_map.hpp"
#include "adit/slam/prior_map_file.hpp"
#include "adit/eval/align.hpp"
#include "adit/eval/associate.hpp"
#include "adit/eval/trajectory_io.hpp"
#include "pipeline_run.hpp"
#include "sim_sessions.hpp"
#include "temp_file.hpp"

namespace adit::test {
namespace {

// Polls `sessions` until its replay has ended (or two minutes).
void run_to_end(daemon::Sessions& sessions) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!sessions.poll() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
}

nlohmann::json read_summary(const std::filesystem::path& dir) {
  std::ifstream in(dir / "summary.json");
  return nlohmann::json::parse(in, nullptr, false);
}

// The largest distance from `from_s` on between the estimate's positions and
// the truth's carried into the estimate's frame by `frame_from_world`.
double worst_error_after(const eval::Associated& a, double from_s, const eval::Similarity& frame_from_world = {}) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.ref.size(); ++i)
    if (a.stamps[i] >= from_s)
      worst = std::max(worst, (a.est[i].translation() - frame_from_world.apply(a.ref[i].translation())).norm());
  return worst;
}

TEST(PriorPipeline, TheOdometryAnchorsToThePriorAndTheSessionIsInItsFrame) {
  const std::filesystem::path session =
      simulated_session("session-building-robot", "--scene building --platform robot --duration 15 --seed 3");
  const TempFolder work;
  const std::filesystem::path prior_dir = work.path() / "prior";
  const CommandRun prepare =
      run_adit(fmt::format("prior-map prepare {} --out {}", (session / "bim.ply").string(), prior_dir.string()));
  ASSERT_EQ(prepare.status, 0) << prepare.output;
  config::Config c = replay_config(session, work.path(), "session:\n  products: false\n");
  c.lidar.replay_speed = 1.0;  // live pace: localisation takes a second or two of a core
  c.prior_map.dir = prior_dir.string();
  std::filesystem::path dir;
  {
    daemon::Sessions sessions(c, {});
    const protocol::LocaliseHint hint;  // HINT reaches the running session's localiser only
    EXPECT_EQ(sessions.hint(hint), "no session is mapping");
    dir = sessions.folder(sessions.start());
    run_to_end(sessions);
    EXPECT_EQ(sessions.hint(hint), "already localised in the prior map");
    sessions.stop_and_wait();
  }
  const nlohmann::json summary = read_summary(dir);
  ASSERT_TRUE(summary.is_object());
  ASSERT_TRUE(summary["prior_map"]["anchored"].get<bool>()) << summary["prior_map"].dump();
  const double anchored_after_s = summary["prior_map"]["anchored_after_s"].get<double>();
  // Within the drive with a second to spare (about 2-3 s on an idle machine; CI runs tests side by side).
  EXPECT_LT(anchored_after_s, 12.0);
  const std::optional<Eigen::Isometry3d> prior_from_odometry = daemon::read_prior_frame(dir / "prior_frame.json");
  ASSERT_TRUE(prior_from_odometry.has_value());
  EXPECT_EQ(summary["frame"]["name"], "prior_map");
  EXPECT_EQ(summary["frame"]["prior_from_odometry"][0][3].get<double>(), prior_from_odometry->translation().x());
  // The simulated odometry frame is not the world's: the anchor moved it.
  EXPECT_GT(prior_from_odometry->translation().norm() + Eigen::AngleAxisd(prior_from_odometry->linear()).angle(), 0.5);

  // The session's trajectory is in the prior's (the world's) frame: it follows the truth with no fit.
  const slam::Trajectory truth = eval::read_tum(session / "truth_body.tum");
  const slam::Trajectory estimate = eval::read_tum(dir / "trajectory.tum");
  const eval::Associated a = eval::associate(truth, estimate, 0.02);
  ASSERT_GT(a.ref.size(), 100U);
  // From a second after the scan the odometry anchored from: the prior pulls
  // the pose in from the localisation's error (σ about 1.5 cm) within a few scans.
  const double worst_after = worst_error_after(a, a.stamps.front() + anchored_after_s + 1.0);
  // And the map lies on the prior, its differences aside: the median point's
  // distance to the prior's plane there, over the points that have one.
  const slam::PriorMap prior = slam::read_prior_map(prior_dir);
  const slam::VoxelHashMap index = slam::index_prior_map(prior);
  const std::vector<protocol::MapPoint> map = protocol::read_map(dir / "map.ply");
  ASSERT_GT(map.size(), 1000U);
  std::vector<float> distances;
  std::size_t checked = 0;
  for (std::size_t i = 0; i < map.size(); i += 10, ++checked) {
    const Eigen::Vector3f q = Eigen::Vector3d(map[i].x, map[i].y, map[i].z).cast<float>();
    if (const slam::MapPlane plane = index.nearest_plane(q, 5); plane.found)
      distances.push_back(std::abs(plane.normal.dot(q - plane.point)));
  }
  ASSERT_GT(distances.size(), checked / 2) << "most map points lie by a plane of the prior";
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  const float median = distances[distances.size() / 2];
  std::printf("anchored after %.1f s; worst position error in the prior's frame after it: %.3f m; map to prior "
              "median %.3f m (%zu of %zu points by a plane)\n", anchored_after_s, worst_after, median, distances.size(),
              checked);
  EXPECT_LT(worst_after, 0.03);
  // 1.5 cm measured (two runs): the range noise and the prior's differences;
  // a map left in the odometry frame lies metres off.
  EXPECT_LT(median, 0.03F);
}

// prior_map.previous_session: a survey carried on after a stop. One session
// maps a drive; the next, on another drive of the same floor, takes that map
// as its prior, localises in it and is written in its frame: its trajectory
// follows its truth carried into the first session's frame (by the first
// session's first pose), with no fit of its own.
TEST(PriorPipeline, TheNextSessionContinuesInThePreviousSessionsFrame) {
  const std::filesystem::path first =
      simulated_session("session-building-robot-30s", "--scene building --platform robot --duration 30 --seed 3");
  const std::filesystem::path second =
      simulated_session("session-building-robot-s2", "--scene building --platform robot --duration 15 --seed 2");
  const TempFolder work;
  const auto run = [](const config::Config& c) {
    daemon::Sessions sessions(c, {});
    const std::filesystem::path dir = sessions.folder(sessions.start());
    run_to_end(sessions);
    sessions.stop_and_wait();
    return dir;
  };
  config::Config c1 = replay_config(first, work.path(), "session:\n  products: false\n");
  c1.lidar.replay_speed = 0.0;  // as fast as it goes: a map is all it must leave
  const std::filesystem::path dir1 = run(c1);
  config::Config c2 = replay_config(second, work.path(), "session:\n  products: false\n");
  c2.lidar.replay_speed = 1.0;
  c2.prior_map.previous_session = true;
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));  // session ids are whole seconds
  const std::filesystem::path dir2 = run(c2);

  const nlohmann::json summary = read_summary(dir2);
  ASSERT_TRUE(summary.is_object());
  EXPECT_EQ(summary["prior_map"]["source"], (dir1 / "map.ply").string());
  ASSERT_TRUE(summary["prior_map"]["anchored"].get<bool>()) << summary["prior_map"].dump();
  EXPECT_EQ(summary["frame"]["name"], "prior_map");

  // The first session's frame in the world, from its first pose (this short
  // out-and-back drive is too straight for a fit of its whole path to fix a roll).
  const eval::Associated a1 =
      eval::associate(eval::read_tum(first / "truth_body.tum"), eval::read_tum(dir1 / "trajectory.tum"), 0.02);
  const std::optional<eval::Similarity> first_from_world = eval::align_trajectory(a1.est, a1.ref, eval::Alignment::origin);
  ASSERT_TRUE(first_from_world.has_value());
  const eval::Associated a2 =
      eval::associate(eval::read_tum(second / "truth_body.tum"), eval::read_tum(dir2 / "trajectory.tum"), 0.02);
  ASSERT_GT(a2.ref.size(), 100U);
  const double worst =
      worst_error_after(a2, a2.stamps.front() + summary["prior_map"]["anchored_after_s"].get<double>() + 1.0,
                        *first_from_world);
  std::printf("second session anchored after %.1f s in the first's map; worst position error in its frame after "
              "it: %.3f m\n", summary["prior_map"]["anchored_after_s"].get<double>(), worst);
  EXPECT_LT(worst, 0.05);  // the first session's own map error is in it
}

TEST(PriorPipeline, WithoutAPriorThereIsNoLocaliser) {
  const TempFolder work;
  config::Config c = replay_config(simulated_session("session-building-robot",
                                                     "--scene building --platform robot --duration 15 --seed 3"),
                                   work.path());
  daemon::PipelineOptions options;
  options.mapping = false;
  const daemon::Pipeline pipeline(c, options);
  EXPECT_EQ(pipeline.prior_localiser(), nullptr);
}

}  // namespace
}  // namespace adit::test
