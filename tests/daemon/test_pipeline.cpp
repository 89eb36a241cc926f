// The whole packet-to-pose pipeline on a real capture: every scan the
// assembly cuts reaches odometry and comes out as a pose, nothing is dropped
// in replay, and the trajectory file has one line per valid pose.

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <span>
#include <sstream>
#include <utility>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/config/load.hpp"
#include "adit/daemon/pipeline.hpp"
#include "adit/daemon/supervisor.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "can_logs.hpp"
#include "shared_data.hpp"

namespace adit::daemon {
namespace {

config::Config hdl32e_replay(const std::filesystem::path& dir, const std::filesystem::path& state) {
  const std::string yaml = fmt::format(
      "payload:\n  id: test\n  state_dir: {}\nlidar:\n  model: HDL-32E\n  source: pcap\n  pcap: {}\n"
      "  calibration: {}\n  replay_speed: 0\nthreads:\n  lock_memory: false\n",
      state.string(), (dir / "capture.pcap").string(), (dir / "HDL32.yaml").string());
  return config::parse_config(yaml, "test.yaml", "/");
}

TEST(Pipeline, ReplaysARealCaptureIntoOnePosePerScan) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-hdl32e");
  const auto out = test::binary_dir() / "pipeline-test";
  std::filesystem::remove_all(out);
  PipelineOptions options;
  options.trajectory_file = out / "trajectory.tum";
  options.map_trajectory_file = out / "map_trajectory.tum";
  // The live grid's changed patches, handed over on the mapping thread (read after join()).
  std::map<std::pair<int, int>, std::int32_t> grid_versions;
  std::size_t grid_cells = 0;
  options.sinks.grid = [&](slam::GridPatchCoord c, std::int32_t version, std::span<const std::int8_t> cells,
                           std::size_t) {
    std::int32_t& held = grid_versions[{c.x, c.y}];
    EXPECT_GT(version, held);
    held = version;
    grid_cells = cells.size();
  };
  Pipeline pipeline(hdl32e_replay(dir, out), options);
  pipeline.start();
  pipeline.join();
  ASSERT_TRUE(pipeline.drained());
  ASSERT_NE(pipeline.grid(), nullptr);
  EXPECT_FALSE(grid_versions.empty());
  EXPECT_LE(grid_versions.size(), pipeline.grid()->patch_count());
  EXPECT_EQ(grid_cells, 128U * 128U);
  for (const auto& [c, version] : grid_versions) EXPECT_EQ(version, pipeline.grid()->version({c.first, c.second}));
  const PipelineStats& s = pipeline.stats();
  EXPECT_GE(s.scans.load(), 5U);  // 876 packets of an 11.7 Hz sensor: about 5 scans
  // Every scan is a pose but an incomplete first one.
  EXPECT_EQ(s.poses.load() + s.skipped_start_scans.load(), s.scans.load());
  EXPECT_LE(s.skipped_start_scans.load(), 1U);
  EXPECT_EQ(s.dropped_packets.load(), 0U);
  EXPECT_EQ(s.dropped_scans.load(), 0U);
  EXPECT_EQ(s.datagrams.load(), 976U);          // 876 data + 100 position packets
  EXPECT_EQ(s.foreign_datagrams.load(), 100U);  // the position packets, on port 8308
  EXPECT_EQ(pipeline.timings().odometry_ms.size(), s.poses.load());
  EXPECT_EQ(pipeline.timings().grid_ms.size(), s.mapped_scans.load());

  std::ifstream trajectory(options.trajectory_file);
  std::size_t lines = 0;
  for (std::string line; std::getline(trajectory, line);) ++lines;
  EXPECT_EQ(lines, s.poses.load() - s.invalid_poses.load());

  // The map's own poses: one per mapped scan, at the same stamps, the map's
  // refinement (map.refine, on by default) moves them a little at most.
  std::ifstream odometry_file(options.trajectory_file);
  std::ifstream map_file(options.map_trajectory_file);
  std::size_t mapped = 0;
  for (std::string a, b; std::getline(map_file, b);) {
    ++mapped;
    ASSERT_TRUE(std::getline(odometry_file, a));
    std::istringstream in_a(a), in_b(b);
    double ta = 0, tb = 0;
    Eigen::Vector3d pa, pb;
    in_a >> ta >> pa.x() >> pa.y() >> pa.z();
    in_b >> tb >> pb.x() >> pb.y() >> pb.z();
    EXPECT_EQ(ta, tb) << mapped;
    EXPECT_LT((pa - pb).norm(), 0.3) << mapped;
  }
  EXPECT_EQ(mapped, s.mapped_scans.load());
  EXPECT_GE(mapped, 5U);
}

TEST(Pipeline, RunsWithACanImuAndNoWheels) {
  // A drone's or a handheld's payload: the IMU alone on the CAN bus
  // (accelerometer and gyroscope), no wheels, with the real capture; the log
  // starts at the capture's first packet and covers it.
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-hdl32e");
  drivers::PcapReader reader(dir / "capture.pcap");
  drivers::UdpDatagram d;
  ASSERT_TRUE(reader.next(d));
  const double t0 = 1e-9 * static_cast<double>(d.capture_time_ns) - 0.5;
  const std::filesystem::path log = test::imu_only_log(3.0, "pipeline-imu", [](int, test::ImuFrames&) {}, t0);
  const auto out = test::binary_dir() / "pipeline-imu-test";
  std::filesystem::remove_all(out);
  std::filesystem::create_directories(out);  // a session's folder exists before its pipeline starts
  config::Config c = hdl32e_replay(dir, out);
  const config::Config imu = test::imu_only_config(log);
  c.can = imu.can;
  c.wheel_odometry = imu.wheel_odometry;
  c.imu = imu.imu;
  PipelineOptions options;
  options.mapping = false;
  Pipeline pipeline(c, options);
  SessionFiles files;
  files.can_record_file = out / "can.log";
  pipeline.start(files);
  pipeline.join();
  ASSERT_TRUE(pipeline.drained());
  const PipelineStats& s = pipeline.stats();
  EXPECT_GE(s.scans.load(), 5U);
  // Every scan is a pose but an incomplete first one.
  EXPECT_EQ(s.poses.load() + s.skipped_start_scans.load(), s.scans.load());
  EXPECT_LE(s.skipped_start_scans.load(), 1U);
  // The IMU's readings reached the odometry (each scan waited for its own), with their gyroscope.
  EXPECT_GT(s.imu.samples.load(), 40U);
  EXPECT_EQ(s.imu.gyro_samples.load(), s.imu.samples.load());
  EXPECT_NEAR(s.imu.rate_hz.load(), 100.0, 1.0);
  EXPECT_EQ(describe_problems(s.imu, "can"), "");
  // No wheels: no wheel prior sought, none counted missing.
  EXPECT_EQ(s.wheel_priors.load() + s.scans_without_wheels.load(), 0U);
  EXPECT_TRUE(std::filesystem::exists(out / "can.log"));
  std::filesystem::remove(log);
}

TEST(Pipeline, StopsOnRequestEvenMidReplay) {
  ADIT_REQUIRE_SHARED_DATA(dir, "lidar/velodyne-hdl32e");
  config::Config config = hdl32e_replay(dir, test::binary_dir() / "pipeline-test-stop");
  config.lidar.replay_speed = 0.1;  // slow: the replay would take 5 s
  Pipeline pipeline(config, {});
  pipeline.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  pipeline.request_stop();
  pipeline.join();
  EXPECT_TRUE(pipeline.drained());
  EXPECT_LT(pipeline.stats().datagrams.load(), 976U);
}

TEST(Pipeline, UnknownFilesAreNamedBeforeAnyThreadStarts) {
  const config::Config config = config::parse_config(
      "payload:\n  id: t\nlidar:\n  model: VLP-16\n  source: pcap\n  pcap: /nonexistent/capture.pcap\n", "t.yaml", "/");
  try {
    Pipeline pipeline(config, {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/capture.pcap"), std::string::npos) << e.what();
  }
}

TEST(Supervisor, AStalledWorkerIsNamedAndFinishedOnesAreNot) {
  Heartbeat a("receiver");
  Heartbeat b("odometry");
  Heartbeat c("output");
  const std::int64_t now = monotonic_ns();
  a.last_ns = now - 100'000'000;
  b.last_ns = now - 5'000'000'000;
  c.last_ns = now - 9'000'000'000;
  c.finished = true;
  const std::vector<const Heartbeat*> beats{&a, &b, &c};
  const SupervisorVerdict v = check_heartbeats(beats, now, 2'000'000'000);
  EXPECT_FALSE(v.healthy);
  EXPECT_EQ(v.stalled, "odometry");
  b.beat();
  EXPECT_TRUE(check_heartbeats(beats, monotonic_ns(), 2'000'000'000).healthy);
}

}  // namespace
}  // namespace adit::daemon
