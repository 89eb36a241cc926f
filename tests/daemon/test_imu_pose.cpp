// The pose at the IMU's rate (daemon/imu_pose_feed.hpp, imu_pose_publisher.hpp):
// on LCM, each as pose_t on ADIT/<payload>/POSE_IMU; from aditd's pipeline on
// a simulated LiDAR-inertial walk, one pose per IMU reading that follows the
// true path as closely as the scan-rate poses do; from aditd itself.

#include <gtest/gtest.h>

#include <lcm/lcm-cpp.hpp>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "../slam/smooth_motion.hpp"
#include "adit/config/load.hpp"
#include "adit/daemon/imu_pose_feed.hpp"
#include "adit/daemon/imu_pose_publisher.hpp"
#include "adit/daemon/pipeline.hpp"
#include "adit/pose_t.hpp"
#include "adit/protocol/channels.hpp"
#include "adit/protocol/checked_decode.hpp"
#include "adit/slam/tum.hpp"
#include "pipeline_run.hpp"
#include "pose_counter.hpp"
#include "run_program.hpp"
#include "sim_sessions.hpp"

namespace adit::daemon {
namespace {

using slam::test::Motion;

constexpr double kRate = 200.0;

TEST(ImuPosePublisher, EachPoseGoesOutOnPoseImu) {
  const std::string url = fmt::format("udpm://239.255.76.67:{}?ttl=0", 20000 + (::getpid() + 23) % 30000);
  const std::string payload = fmt::format("imu{}", ::getpid());
  lcm::LCM listener(url);
  std::vector<pose_t> received;
  struct Handler {
    std::vector<pose_t>* out;
    void on(const lcm::ReceiveBuffer* rbuf, const std::string&) {
      pose_t p;
      if (protocol::checked_decode(rbuf->data, rbuf->data_size, p)) out->push_back(p);
    }
  } handler{&received};
  listener.subscribe(protocol::channel_name(payload, protocol::Channel::imu_pose), &Handler::on, &handler);

  ImuPosePublisher publisher(url, payload);
  const Motion m;
  slam::Matrix6d covariance;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) covariance(r, c) = 1e-4 * (r == c ? 10.0 + r : 0.1 * (r + c));
  for (int k = 0; k < 20; ++k) {
    publisher.publish(m.state(1.0 + k / kRate), covariance);
  }
  for (int i = 0; i < 100 && received.size() < 20; ++i) listener.handleTimeout(20);
  ASSERT_EQ(received.size(), 20U);
  EXPECT_EQ(publisher.published(), 20U);
  for (std::size_t k = 0; k < received.size(); ++k) {
    const pose_t& p = received[k];
    const double t = 1.0 + static_cast<double>(k) / kRate;
    EXPECT_EQ(p.seq, static_cast<std::int64_t>(k));
    EXPECT_EQ(p.utime, static_cast<std::int64_t>(t * 1e6));
    EXPECT_EQ(p.flags, pose_t::FLAG_VALID);
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) EXPECT_EQ(p.covariance[6 * r + c], covariance(r, c)) << r << "," << c;  // row-major
    const Eigen::Vector3d truth = m.position(t);
    EXPECT_NEAR(p.position[0], truth.x(), 1e-9);
    EXPECT_NEAR(p.position[2], truth.z(), 1e-9);
    const Eigen::Quaterniond q(m.rotation(t));
    EXPECT_NEAR(std::abs(p.orientation[0] * q.w() + p.orientation[1] * q.x() + p.orientation[2] * q.y() +
                         p.orientation[3] * q.z()),
                1.0, 1e-9);
  }
}

// The configurations whose IMU-rate pose runs on a thread without a
// real-time policy say so at start (decision 041); the payload template's
// SCHED_FIFO receiver does not.
TEST(ImuPosePublisher, AConfigurationThatCannotKeepTwoMillisecondsSaysWhy) {
  config::Config c;
  c.imu.enabled = true;
  c.imu.pose_horizon_s = 0.1;
  c.imu.source = config::ImuSource::ouster;
  const std::optional<std::string> other = imu_pose_latency_warning(c);
  ASSERT_TRUE(other.has_value());
  EXPECT_NE(other->find("threads.receiver"), std::string::npos) << *other;
  c.threads.receiver.policy = config::SchedPolicy::fifo;
  EXPECT_FALSE(imu_pose_latency_warning(c).has_value());
  c.imu.source = config::ImuSource::can;
  const std::optional<std::string> can = imu_pose_latency_warning(c);
  ASSERT_TRUE(can.has_value());
  EXPECT_NE(can->find("CAN thread"), std::string::npos) << *can;
  c.imu.pose_horizon_s = 0.0;  // no IMU-rate pose published
  EXPECT_FALSE(imu_pose_latency_warning(c).has_value());
  c.imu.pose_horizon_s = 0.1;
  c.imu.enabled = false;
  EXPECT_FALSE(imu_pose_latency_warning(c).has_value());
}

// aditd's pipeline replaying a simulated hand-held walk (OS1-64, its IMU at
// 100 Hz in the same capture) at the recorded pace, as a live sensor sends
// it: a pose per IMU reading, scored against the truth as the scan-rate
// trajectory is. (A CAN log is read ahead of the LiDAR in a replay: its
// readings pass the horizon, and the IMU-rate pose is a live matter there.)
TEST(ImuPose, ThePipelineGivesAPosePerImuReadingThatFollowsTheTruth) {
  const std::filesystem::path session = test::handheld_os1_9s();
  const std::filesystem::path work = test::binary_dir() / fmt::format("imu-pose-{}", ::getpid());
  std::filesystem::remove_all(work);
  config::Config c = config::load_config(session / "session.yaml");
  c.payload.state_dir = (work / "state").string();
  c.threads.lock_memory = false;
  ASSERT_TRUE(c.imu.enabled);
  ASSERT_EQ(c.lidar.replay_speed, 1.0);
  slam::Trajectory imu_rate;
  imu_rate.stamps.reserve(4000);
  imu_rate.poses.reserve(4000);
  PipelineOptions options;
  options.trajectory_file = work / "trajectory.tum";
  options.mapping = false;
  std::size_t unusable_covariances = 0;
  std::vector<double> sigma_m;  // the largest position σ of each pose
  sigma_m.reserve(4000);
  options.sinks.imu_pose = [&](const slam::InertialState& s, const slam::Matrix6d& covariance) {
    imu_rate.stamps.push_back(s.t);
    imu_rate.poses.push_back(s.pose);
    // Each pose carries the filter's covariance: symmetric, positive on the diagonal.
    const bool usable = covariance.allFinite() && (covariance - covariance.transpose()).norm() <= 1e-9 * covariance.norm() &&
                        (covariance.diagonal().array() > 0.0).all();
    unusable_covariances += usable ? 0 : 1;
    if (usable) sigma_m.push_back(std::sqrt(covariance.topLeftCorner<3, 3>().diagonal().maxCoeff()));
  };
  Pipeline pipeline(c, options);
  pipeline.start();
  pipeline.join();
  ASSERT_NE(pipeline.imu_poses(), nullptr);
  EXPECT_EQ(pipeline.imu_poses()->poses(), imu_rate.size());
  // 9 s at 100 Hz, from the first LiDAR-inertial scan on.
  EXPECT_GE(imu_rate.size(), 800U);
  EXPECT_EQ(unusable_covariances, 0U);
  // Uncertain while the filter learns the walker's velocity at the start
  // (0.3-0.5 m), then centimetres (3-16 mm on this walk, whose poses are
  // within 6 mm of the truth), and never confident past the scan's own.
  ASSERT_GT(sigma_m.size(), 100U);
  const double settled_worst = *std::max_element(sigma_m.begin() + 100, sigma_m.end());
  std::printf("position sigma on POSE_IMU: first %.3f m, after the first second at most %.4f m\n", sigma_m.front(),
              settled_worst);
  EXPECT_GT(sigma_m.front(), 0.1);
  EXPECT_LT(settled_worst, 0.05);
  EXPECT_GT(settled_worst, 0.001);
  slam::write_tum(work / "imu_rate.tum", imu_rate);

  const auto ape = [&](const std::filesystem::path& est) {
    const test::CommandRun eval = test::run_adit(fmt::format("eval traj --ref {} --est {} --json",
                                                             (session / "truth_body.tum").string(), est.string()));
    EXPECT_EQ(eval.status, 0) << eval.output;
    return nlohmann::json::parse(eval.output.substr(eval.output.find('{')))["ape"]["translation_m"];
  };
  const nlohmann::json scans = ape(work / "trajectory.tum");
  const nlohmann::json readings = ape(work / "imu_rate.tum");
  std::printf("APE at scan rate: rmse %.4f m, max %.4f m; at the IMU's rate: rmse %.4f m, max %.4f m\n",
              scans["rmse"].get<double>(), scans["max"].get<double>(), readings["rmse"].get<double>(),
              readings["max"].get<double>());
  // Carried at most a scan and its registration past the scan: within a
  // centimetre of the scan-rate poses' error.
  EXPECT_LT(readings["rmse"].get<double>(), scans["rmse"].get<double>() + 0.01);
  EXPECT_LT(readings["max"].get<double>(), scans["max"].get<double>() + 0.01);
}

// aditd as a flight controller meets it: the hand-held walk replayed at its
// pace, the IMU-rate pose on ADIT/<payload>/POSE_IMU beside the scan-rate one.
TEST(ImuPose, AditdSendsItOnPoseImuAtTheImuRate) {
  const std::filesystem::path session = test::handheld_os1_9s();
  const std::filesystem::path work = test::binary_dir() / fmt::format("imu-pose-aditd-{}", ::getpid());
  std::filesystem::remove_all(work);
  std::filesystem::create_directories(work);
  const std::string payload = fmt::format("imuaditd{}", ::getpid());
  const std::string url = fmt::format("udpm://239.255.76.67:{}?ttl=0", 20000 + (::getpid() + 31) % 30000);
  std::string yaml =
      test::aditd_yaml_for(session, work / "state", {payload, url, false, "threads:\n  lock_memory: false\n"});
  // A horizon of 2 s: a sanitizer build's odometry, mapping beside it, lags
  // the replay by its whole scan queue (0.5 s), which the default would cut.
  const std::string imu_section = "\nimu:\n  enabled: true\n";
  ASSERT_NE(yaml.find(imu_section), std::string::npos) << yaml;
  yaml.replace(yaml.find(imu_section), imu_section.size(), imu_section + "  pose_horizon_s: 2\n");
  const std::filesystem::path config = work / "aditd.yaml";
  std::ofstream(config) << yaml;
  test::PoseCounter scans(url, payload);
  test::PoseCounter imu_rate(url, payload, protocol::Channel::imu_pose);
  test::Daemon aditd({(test::binary_dir() / "bin/aditd").string(), "--config", config.string(), "--once"},
                     work / "aditd.log");
  ASSERT_EQ(aditd.wait_exit(90), 0) << "see " << (work / "aditd.log").string();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the last messages in flight
  std::printf("POSE: %zu, POSE_IMU: %zu\n", scans.count(), imu_rate.count());
  // 100 Hz over the 9 s walk from the first LiDAR-inertial scan on, 10 Hz on POSE.
  EXPECT_GE(imu_rate.count(), 750U);
  EXPECT_EQ(imu_rate.valid(), imu_rate.count());
  EXPECT_GE(imu_rate.count(), 8 * scans.count());
}

}  // namespace
}  // namespace adit::daemon
