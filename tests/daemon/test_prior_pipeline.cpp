// aditd's pipeline with a prior map (prior_map.dir) on a simulated building
// drive replayed at its own pace: thread "prior" localises the odometry's
// first scans, the odometry anchors to the prior, the anchor is written to the
// session's prior_frame.json, and the trajectory placed by it follows the
// truth in the prior's (the world's) frame from then on.
#include <gtest/gtest.h>

#include <fstream>

#include <nlohmann/json.hpp>

#include "adit/daemon/pipeline.hpp"
#include "adit/daemon/prior_localiser.hpp"
#include "adit/eval/associate.hpp"
#include "adit/eval/trajectory_io.hpp"
#include "pipeline_run.hpp"
#include "sim_sessions.hpp"
#include "temp_file.hpp"

namespace adit::test {
namespace {

TEST(PriorPipeline, TheOdometryAnchorsToThePriorAndFollowsItsFrame) {
  const std::filesystem::path session =
      simulated_session("session-building-robot", "--scene building --platform robot --duration 15 --seed 3");
  const TempFolder work;
  const CommandRun prepare =
      run_adit(fmt::format("prior-map prepare {} --out {}", (session / "bim.ply").string(), (work.path() / "prior").string()));
  ASSERT_EQ(prepare.status, 0) << prepare.output;
  config::Config c = replay_config(session, work.path());
  c.lidar.replay_speed = 1.0;  // live pace: localisation takes a second or two of a core
  c.prior_map.dir = (work.path() / "prior").string();
  daemon::PipelineOptions options;
  options.mapping = false;
  options.trajectory_file = work.path() / "trajectory.tum";
  daemon::Pipeline pipeline(c, options);
  ASSERT_NE(pipeline.prior_localiser(), nullptr);
  daemon::SessionFiles files;
  files.prior_frame_file = work.path() / "prior_frame.json";
  pipeline.start(files);
  pipeline.join();

  const daemon::PriorLocaliserStats& stats = pipeline.prior_localiser()->stats();
  ASSERT_TRUE(stats.anchored.load()) << stats.tries.load() << " tries";
  // Within the drive with a second to spare (about 2-3 s on an idle machine; CI runs tests side by side).
  EXPECT_LT(stats.anchored_after_s.load(), 12.0);
  std::ifstream in(files.prior_frame_file);
  ASSERT_TRUE(in.good());
  const auto j = nlohmann::json::parse(in);
  Eigen::Isometry3d prior_from_odometry = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 4; ++r)
    for (int col = 0; col < 4; ++col) prior_from_odometry.matrix()(r, col) = j["prior_from_odometry"][r][col].get<double>();

  const slam::Trajectory truth = eval::read_tum(session / "truth_body.tum");
  const slam::Trajectory estimate = eval::read_tum(work.path() / "trajectory.tum");
  const eval::Associated a = eval::associate(truth, estimate, 0.02);
  ASSERT_GT(a.ref.size(), 100U);
  double worst_after = 0.0;
  // From a second after the scan the odometry anchored from: the prior pulls
  // the pose in from the localisation's error (σ about 1.5 cm) within a few scans.
  const double anchored_from = a.stamps.front() + stats.anchored_after_s.load() + 1.0;
  for (std::size_t i = 0; i < a.ref.size(); ++i) {
    if (a.stamps[i] < anchored_from) continue;
    worst_after = std::max(worst_after, ((prior_from_odometry * a.est[i]).translation() - a.ref[i].translation()).norm());
  }
  std::printf("anchored after %.1f s (%llu tries); worst position error in the prior's frame after it: %.3f m\n",
              stats.anchored_after_s.load(), static_cast<unsigned long long>(stats.tries.load()), worst_after);
  EXPECT_LT(worst_after, 0.03);
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
