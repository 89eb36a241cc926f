// The odometry step aditd's odometry stage and `adit bench odometry` share:
// the scan in the body frame with its firing times, and the wheels' prior
// and gravity's up taken from the CAN feed for every scan they cover.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>

#include <fmt/format.h>

#include "adit/daemon/can_feed.hpp"
#include "adit/daemon/scan_odometry.hpp"
#include "adit/daemon/sessions.hpp"
#include "adit/pose_t.hpp"
#include "can_logs.hpp"

namespace adit::daemon {
namespace {

drivers::LidarPoint point(float x, float y, float z, std::uint32_t time_offset_ns) {
  drivers::LidarPoint p;
  p.x = x;
  p.y = y;
  p.z = z;
  p.time_offset_ns = time_offset_ns;
  return p;
}

// A 10 m × 6 m × 3 m room around the sensor, swept over 0.1 s.
drivers::LidarScan room_scan(std::int64_t start_ns) {
  drivers::LidarScan scan;
  scan.start_time_ns = start_ns;
  for (int i = 0; i < 2000; ++i) {
    const double a = 2.0 * M_PI * i / 2000.0;
    const double c = std::cos(a);
    const double s = std::sin(a);
    const double r = std::min(5.0 / std::max(std::abs(c), 1e-6), 3.0 / std::max(std::abs(s), 1e-6));
    const auto t = static_cast<std::uint32_t>(1e8 * i / 2000.0);
    const float z = static_cast<float>((i % 5) * 0.5 - 1.0);
    scan.points.push_back(point(static_cast<float>(r * c), static_cast<float>(r * s), z, t));
  }
  scan.stats.complete = true;
  return scan;
}

TEST(ScanOdometry, PutsTheScanInTheBodyFrameWithItsFiringTimes) {
  config::Config c;
  c.lidar.extrinsics.xyz_m = {0.2, 0.0, 0.5};
  c.lidar.extrinsics.rpy_deg = {0.0, 0.0, 90.0};  // the sensor's x is the body's y
  ScanOdometry odometry(c, odometry_config_of(c, {}, 16), nullptr, [] { return true; });
  drivers::LidarScan scan;
  scan.start_time_ns = 1'000'000'000;
  scan.points = {point(1.0F, 0.0F, 0.0F, 0), point(0.0F, 2.0F, 0.0F, 50'000'000)};
  odometry.process(scan);
  ASSERT_EQ(odometry.body_points().size(), 2U);
  EXPECT_TRUE(odometry.body_points()[0].isApprox(Eigen::Vector3f(0.2F, 1.0F, 0.5F), 1e-6F));
  EXPECT_TRUE(odometry.body_points()[1].isApprox(Eigen::Vector3f(-1.8F, 0.0F, 0.5F), 1e-6F));
  EXPECT_FLOAT_EQ(odometry.body_times()[1], 0.05F);
  EXPECT_EQ(odometry.counts().wheel_priors + odometry.counts().gravity_priors, 0U) << "no CAN bus configured";
}

std::filesystem::path binary_dir_log(const std::string& name) {
  return test::binary_dir() / fmt::format("{}-{}.log", name, ::getpid());
}

// The odometry step on a replayed CAN log; the log is removed at the end.
struct OnReplayedCan {
  explicit OnReplayedCan(const config::Config& config)
      : log(config.can.log), can(config), odometry(config, odometry_config_of(config, {}, 2000), &can, [] { return true; }) {
    can.start({});
  }
  ~OnReplayedCan() { std::filesystem::remove(log); }
  // Scans every 0.1 s from `first_ns`; then the feed stops.
  const MotionAidCounts& run(std::int64_t first_ns, int scans) {
    for (int k = 0; k < scans; ++k) odometry.process(room_scan(first_ns + k * 100'000'000LL));
    can.stop();
    return odometry.counts();
  }
  std::filesystem::path log;
  CanFeed can;
  ScanOdometry odometry;
};

TEST(ScanOdometry, TakesTheWheelsPriorAndGravityFromAReplayedCanLog) {
  config::Config c = test::wheel_config(test::straight_drive_log(3.0, "scan-odometry", true));
  test::add_accelerometer(c);
  OnReplayedCan replay(c);
  const MotionAidCounts& counts = replay.run(1'000'500'000'000, 10);
  // The first scan has no previous one to take the wheels' motion from; every
  // scan has the accelerometer's readings over its sweep.
  EXPECT_EQ(counts.wheel_priors, 9U);
  EXPECT_EQ(counts.scans_without_wheels, 0U);
  EXPECT_EQ(counts.gravity_priors, 10U);
  EXPECT_EQ(counts.scans_without_gravity, 0U);
}

TEST(ScanOdometry, CountsScansTheCanLogDoesNotCover) {
  OnReplayedCan replay(test::wheel_config(test::straight_drive_log(1.0, "scan-odometry-short")));
  // The log covers 1000-1001 s; these scans lie after it.
  const MotionAidCounts& counts = replay.run(1'005'000'000'000, 3);
  EXPECT_EQ(counts.wheel_priors, 0U);
  EXPECT_EQ(counts.scans_without_wheels, 2U);
}

// The left wheel spins at 2 m/s for 0.3 s of a 1 m/s drive (from 1001.0 s):
// the wheel odometry holds it (a slip), and the scans over which it is held
// get no wheel prior (their motion is a guess), counted apart from scans the
// log does not cover.
TEST(ScanOdometry, TakesNoWheelPriorOverAWheelHeldForSlip) {
  const std::filesystem::path log = binary_dir_log("scan-odometry-slip");
  {
    std::ofstream out(log);
    for (int i = 0; i <= 300; ++i) {
      const double t = 1000.0 + 0.01 * i;
      const bool slipping = t >= 1001.0 && t < 1001.3;
      out << fmt::format("({:.6f}) can0 300#{}E803\n", t, slipping ? "D007" : "E803");
    }
  }
  OnReplayedCan replay(test::wheel_config(log));
  const MotionAidCounts& counts = replay.run(1'000'500'000'000, 20);  // scans 1000.5-1002.4 s
  EXPECT_GE(counts.scans_wheels_held, 3U) << "the scans from 1000.9 to 1001.3 s";
  EXPECT_LE(counts.scans_wheels_held, 6U) << "and not those before or well after";
  EXPECT_EQ(counts.scans_without_wheels, 0U);
  EXPECT_EQ(counts.wheel_priors + counts.scans_wheels_held, 19U);
}

// Gyrodometry (decision 052): a robot stands still for a second, then drives
// straight at 1 m/s on wheels whose speeds differ by 2 % (a false turn of
// 0.04 rad/s), with a gyroscope whose bias is (0.002, -0.001, 0.004) rad/s.
// The standstill teaches the bias; the priors then turn as the gyroscope
// turns, with its bias removed, not as the wheels do.
// `stuck_z` (counts of 0.0002 rad/s) replaces the gyroscope's z from 1001.5 s when given.
std::filesystem::path drive_with_gyro_log(const std::string& name, std::optional<int> stuck_z = std::nullopt) {
  const std::filesystem::path log = binary_dir_log(name);
  std::ofstream out(log);
  for (int i = 0; i <= 300; ++i) {
    const double t = 1000.0 + 0.01 * i;
    const double speed = std::clamp(2.0 * (t - 1001.0), 0.0, 1.0);  // 2 m/s² from 1001 s
    const auto mm = [](double v) { return test::int16_le({static_cast<int>(std::lround(1000.0 * v)), 0, 0}).substr(0, 4); };
    out << fmt::format("({:.6f}) can0 300#{}{}\n", t, mm(1.01 * speed), mm(0.99 * speed));
    out << fmt::format("({:.6f}) can0 190#{}\n", t + 0.0003, test::int16_le({0, 0, 9807}));
    const int noise = i % 2 == 0 ? 1 : -1;  // a count either way: a real gyroscope's axes never read one value
    const int z = stuck_z && t >= 1001.5 ? *stuck_z : 20 + noise;
    out << fmt::format("({:.6f}) can0 191#{}\n", t + 0.0004, test::int16_le({10 + noise, -5 - noise, z}));  // 0.0002 rad/s a count
  }
  return log;
}

config::Config wheels_and_gyro_config(const std::filesystem::path& log) {
  config::Config c = test::wheel_config(log);
  const config::Config imu = test::imu_only_config(log);
  c.can.signals.insert(c.can.signals.end(), imu.can.signals.begin(), imu.can.signals.end());
  c.imu = imu.imu;
  return c;
}

TEST(ScanOdometry, TurnsTheWheelsPriorWithTheGyroscopeWhoseBiasItLearntStandingStill) {
  OnReplayedCan replay(wheels_and_gyro_config(drive_with_gyro_log("scan-odometry-gyro")));
  double largest_turn = 0.0;
  for (int k = 0; k < 20; ++k) {  // scans 1000.5-1002.4 s
    replay.odometry.process(room_scan(1'000'500'000'000 + k * 100'000'000LL));
    const auto& prior = replay.odometry.wheel_prior();
    if (k >= 12 && prior) largest_turn = std::max(largest_turn, Eigen::AngleAxisd(prior->delta.linear()).angle());
  }
  replay.can.stop();
  const MotionAidCounts& counts = replay.odometry.counts();
  EXPECT_EQ(counts.gyro_priors, counts.wheel_priors);
  EXPECT_EQ(counts.wheel_priors, 19U);
  EXPECT_GE(counts.gyro_still, 4U) << "the scans from 1000.5 to 1001.0 s";
  EXPECT_LE(counts.gyro_still, 6U);
  EXPECT_LT((replay.odometry.gyro_bias().bias() - Eigen::Vector3d(0.002, -0.001, 0.004)).norm(), 5e-5)
      << replay.odometry.gyro_bias().bias().transpose();
  // The wheels turn 0.02 m/s across 0.5 m: 0.004 rad a scan; the gyroscope, its bias removed, none.
  EXPECT_LT(largest_turn, 1e-4) << "the wheels alone turn 0.004 rad a scan";
}

// From 1001.5 s the gyroscope's z reads 0.3 rad/s, one value (stuck), while
// the wheels turn 0.004 rad a scan: the wheels' turn stands.
TEST(ScanOdometry, KeepsTheWheelsTurnWhenTheGyroscopeDisagreesWithThem) {
  OnReplayedCan replay(wheels_and_gyro_config(drive_with_gyro_log("scan-odometry-stuck-gyro", 1500)));
  double last_yaw = 0.0;
  for (int k = 0; k < 20; ++k) {
    replay.odometry.process(room_scan(1'000'500'000'000 + k * 100'000'000LL));
    if (replay.odometry.wheel_prior()) last_yaw = Eigen::AngleAxisd(replay.odometry.wheel_prior()->delta.linear()).angle();
  }
  replay.can.stop();
  const MotionAidCounts& counts = replay.odometry.counts();
  EXPECT_GE(counts.gyro_refused, 8U) << "the scans from 1001.6 s";
  EXPECT_EQ(counts.gyro_refused + counts.gyro_priors, counts.wheel_priors);
  EXPECT_NEAR(last_yaw, 0.02 / 0.5 * 0.1, 2e-4) << "the wheels' turn, not the gyroscope's 0.03 rad";
}

TEST(ScanOdometry, KeepsTheWheelsTurnWithoutGyrodometry) {
  config::Config c = wheels_and_gyro_config(drive_with_gyro_log("scan-odometry-no-gyro"));
  c.imu.gyro_with_wheels = false;
  OnReplayedCan replay(c);
  double last_yaw = 0.0;
  for (int k = 0; k < 20; ++k) {
    replay.odometry.process(room_scan(1'000'500'000'000 + k * 100'000'000LL));
    if (replay.odometry.wheel_prior()) last_yaw = Eigen::AngleAxisd(replay.odometry.wheel_prior()->delta.linear()).angle();
  }
  replay.can.stop();
  EXPECT_EQ(replay.odometry.counts().gyro_priors, 0U);
  EXPECT_NEAR(last_yaw, 0.02 / 0.5 * 0.1, 2e-4);
}

TEST(ScanOdometry, RunsOnACanImuWithoutWheelsAndKeepsItsReadingsForEachScan) {
  // A drone's bus: the IMU alone (accelerometer and gyroscope, 100 Hz over 3 s).
  OnReplayedCan replay(test::imu_only_config(test::imu_only_log(3.0, "scan-odometry-imu", [](int, test::ImuFrames&) {})));
  ASSERT_NE(replay.odometry.imu(), nullptr);
  EXPECT_EQ(replay.odometry.imu(), static_cast<const ImuSource*>(&replay.can));
  for (int k = 0; k < 10; ++k) {
    const std::int64_t stamp = 1'000'500'000'000 + k * 100'000'000LL;
    replay.odometry.process(room_scan(stamp));
    // Each scan waited for the readings over its sweep (and 50 ms more), not for wheels.
    EXPECT_GE(replay.odometry.imu()->history().latest(), 1e-9 * static_cast<double>(stamp) + 0.1) << k;
    EXPECT_TRUE(replay.odometry.imu()->history().mean(1e-9 * static_cast<double>(stamp),
                                                        1e-9 * static_cast<double>(stamp) + 0.1).has_value()) << k;
  }
  replay.can.stop();
  const MotionAidCounts& counts = replay.odometry.counts();
  // No wheels: no prior and nothing counted missing; the up needs the wheels' acceleration.
  EXPECT_EQ(counts.wheel_priors + counts.scans_without_wheels, 0U);
  EXPECT_EQ(counts.gravity_priors + counts.scans_without_gravity, 0U);
  EXPECT_GT(replay.can.imu_stats().gyro_samples.load(), 100U);
}

// The odometry's status reaches the tablet as pose_t flags (decision 043):
// a lost scan is held and not valid, the first one tracked again says so.
TEST(PoseSample, EachOdometryStatusCarriesItsFlags) {
  const auto flags_of = [](slam::OdometryStatus status, bool valid) {
    slam::OdometryResult r;
    r.status = status;
    r.valid = valid;
    return pose_sample_of(r).flags;
  };
  // pose_t's flags are unnamed enumerators, one enumeration each.
  const std::int32_t valid = adit::pose_t::FLAG_VALID;
  const std::int32_t held = adit::pose_t::FLAG_HELD;
  EXPECT_EQ(flags_of(slam::OdometryStatus::ok, true), valid);
  EXPECT_EQ(flags_of(slam::OdometryStatus::degenerate, true), valid | adit::pose_t::FLAG_DEGENERATE);
  EXPECT_EQ(flags_of(slam::OdometryStatus::too_few_points, false), held);
  EXPECT_EQ(flags_of(slam::OdometryStatus::lost, false), held | adit::pose_t::FLAG_LOST);
  EXPECT_EQ(flags_of(slam::OdometryStatus::relocalised, true), valid | adit::pose_t::FLAG_RELOCALISED);
}

}  // namespace
}  // namespace adit::daemon
