// The motion sensors failing as they do in the field, on simulated drives
// replayed through the whole pipeline:
// - the CAN bus goes bus-off for 1 s (a loose connector, a babbling node):
//   candump -L logs the error frames (CAN_ERR_BUSOFF, then CAN_ERR_RESTARTED)
//   and nothing else meanwhile: wheels and accelerometer silent;
// - the IMU drops out for 3 s on a drone (its frames missing, the LiDAR
//   running), so LiDAR-inertial odometry runs on the LiDAR alone meanwhile.
// Each is counted by name and the trajectory stays on the simulated truth as
// the fault-free run's does.
#include <gtest/gtest.h>

#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/config/load.hpp"
#include "adit/daemon/can_feed.hpp"
#include "adit/daemon/imu_stats.hpp"
#include "adit/daemon/pipeline.hpp"
#include "adit/drivers/can/bus_status.hpp"
#include "daemon_process.hpp"
#include "pipeline_run.hpp"
#include "run_program.hpp"
#include "shared_data.hpp"
#include "sim_sessions.hpp"

namespace adit::daemon {
namespace {

// `adit faults can IN OUT ARGS`: the log with the bus off or some ids missing.
std::filesystem::path faulty_log(const std::filesystem::path& in, const std::filesystem::path& out,
                                 const std::string& args) {
  const test::CommandRun run = test::run_adit(fmt::format("faults can {} {} {}", in.string(), out.string(), args));
  EXPECT_EQ(run.status, 0) << run.output;
  return out;
}

struct FaultRun {
  std::uint64_t poses = 0;
  double ape_rmse_m = 0.0;
  double end_error_m = 0.0;
  std::uint64_t bus_off = 0, recoveries = 0, error_frames = 0;
  int bus_state = -1;
  std::uint64_t imu_gaps = 0;
  double longest_imu_gap_s = 0.0;
  std::string imu_problems;
};

FaultRun map_with(const std::filesystem::path& session, const std::filesystem::path& can_log,
                  const std::filesystem::path& work) {
  const test::ScoredRun scored = test::run_and_score(session, work, [&](config::Config& c) { c.can.log = can_log.string(); });
  const Pipeline& pipeline = *scored.pipeline;
  FaultRun run;
  run.poses = pipeline.stats().poses.load();
  if (const CanFeedStats* can = pipeline.can_stats()) {
    run.bus_off = can->bus_off.load();
    run.recoveries = can->recoveries.load();
    run.error_frames = can->error_frames.load();
    run.bus_state = can->bus_state.load();
  }
  const ImuStats& imu = pipeline.stats().imu;
  run.imu_gaps = imu.count(ImuProblem::gap);
  run.longest_imu_gap_s = imu.longest_gap_s.load();
  run.imu_problems = describe_problems(imu, "can");
  run.ape_rmse_m = scored.ape_rmse_m;
  run.end_error_m = scored.ape_max_m;
  return run;
}

std::filesystem::path work_dir(const std::string& name) {
  const std::filesystem::path work = test::binary_dir() / fmt::format("{}-{}", name, ::getpid());
  std::filesystem::remove_all(work);
  std::filesystem::create_directories(work);
  return work;
}

TEST(SensorFaults, CanBusOffForOneSecondIsCountedRecoveredAndTheTrajectoryHolds) {
  const std::filesystem::path session = test::mine_drive_12s();
  const std::filesystem::path work = work_dir("bus-off");
  const FaultRun clean = map_with(session, session / "can.log", work / "clean");
  EXPECT_EQ(clean.bus_off, 0U);
  // The controller's own error frames at the edges of the silence; nothing else gets through meanwhile.
  const std::filesystem::path log = faulty_log(session / "can.log", work / "bus-off.log", "--bus-off 4:1");
  const FaultRun r = map_with(session, log, work / "faulty");
  EXPECT_EQ(r.error_frames, 2U);
  EXPECT_EQ(r.bus_off, 1U);
  EXPECT_EQ(r.recoveries, 1U);
  EXPECT_EQ(r.bus_state, static_cast<int>(drivers::can::BusState::ok));
  EXPECT_GE(r.imu_gaps, 1U) << "the accelerometer fell silent with the bus";
  EXPECT_NEAR(r.longest_imu_gap_s, 1.0, 0.05);
  EXPECT_GE(r.poses + 2, clean.poses) << "the LiDAR went on: every scan posed";
  EXPECT_LT(r.ape_rmse_m, clean.ape_rmse_m + 0.05) << "clean " << clean.ape_rmse_m;
  std::printf("bus-off 1 s: APE rmse %.4f m (clean %.4f m), poses %llu (clean %llu)\n", r.ape_rmse_m,
              clean.ape_rmse_m, static_cast<unsigned long long>(r.poses),
              static_cast<unsigned long long>(clean.poses));
  std::filesystem::remove_all(work);
}

TEST(SensorFaults, ImuDropoutOfThreeSecondsOnADroneIsCountedAndTheOdometryCarriesOn) {
  const std::filesystem::path session = test::binary_dir() / "drone-20s-3";
  if (!std::filesystem::exists(session / "lidar.pcap")) {
    const test::CommandRun sim = test::run_adit(fmt::format(
        "sim --scene mine --platform drone --sensor VLP-16 --duration 20 --seed 3 --out {}", session.string()));
    ASSERT_EQ(sim.status, 0) << sim.output;
  }
  const std::filesystem::path work = work_dir("imu-dropout");
  const FaultRun clean = map_with(session, session / "can.log", work / "clean");
  EXPECT_EQ(clean.imu_gaps, 0U) << clean.imu_problems;
  // The IMU's frames (accelerometer 0x190, gyroscope 0x191) missing from 8 s to 11 s.
  const std::filesystem::path log = faulty_log(session / "can.log", work / "dropout.log", "--drop 8:3 --drop-ids 0x190,0x191");
  const FaultRun r = map_with(session, log, work / "faulty");
  EXPECT_EQ(r.imu_gaps, 1U) << r.imu_problems;
  EXPECT_NEAR(r.longest_imu_gap_s, 3.0, 0.02);
  EXPECT_NE(r.imu_problems.find("1 gap (longest 3.0"), std::string::npos) << r.imu_problems;
  EXPECT_GE(r.poses + 2, clean.poses) << "every scan posed through the dropout";
  EXPECT_LT(r.ape_rmse_m, clean.ape_rmse_m + 0.05) << "clean " << clean.ape_rmse_m;
  std::printf("IMU dropout 3 s: APE rmse %.4f m, max %.4f m (clean %.4f, %.4f m), poses %llu (clean %llu)\n",
              r.ape_rmse_m, r.end_error_m, clean.ape_rmse_m, clean.end_error_m,
              static_cast<unsigned long long>(r.poses), static_cast<unsigned long long>(clean.poses));
  std::filesystem::remove_all(work);
}

}  // namespace
}  // namespace adit::daemon
