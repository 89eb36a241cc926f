// The daemon's CAN feed: a replayed candump log decoded into wheel poses
// and accelerometer readings, handed to the odometry thread's histories
// without losing the window that the next scans need, however long the log.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include <Eigen/Geometry>
#include <fstream>
#include <thread>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/daemon/can_feed.hpp"
#include "adit/daemon/can_imu_pairing.hpp"
#include "adit/drivers/can/bus_status.hpp"
#include "can_logs.hpp"
#include "shared_data.hpp"

namespace adit::daemon {
namespace {

using namespace std::chrono_literals;

TEST(CanFeed, AReplayedLogLongerThanTheHistoryStillCoversEveryScan) {
  // 200 s at 100 Hz: 20 000 samples, more than the hand-off (1024) and the history (8192) hold.
  const std::filesystem::path log = test::straight_drive_log(200.0, "wheel-feed");
  CanFeed feed(test::wheel_config(log));
  ASSERT_TRUE(feed.replay());
  feed.start({});
  slam::WheelHistory history(8192);
  double previous = 1000.05;
  int covered = 0;
  int scans = 0;
  for (double t = 1000.15; t < 1199.9; t += 0.1) {  // a scan every 0.1 s, as the odometry thread asks
    ++scans;
    feed.drain_into(history, t);
    for (int i = 0; i < 2000 && history.latest() < t && !feed.finished(); ++i) {
      std::this_thread::sleep_for(1ms);
      feed.drain_into(history, t);
    }
    const auto prior = history.prior(previous, t);
    if (prior && std::abs(prior->delta.translation().x() - (t - previous)) < 1e-6) ++covered;
    previous = t;
  }
  // The log runs 0.1 s past the last scan: let the feed read it to its end
  // before stopping it (stop() ends the thread wherever it is).
  for (int i = 0; i < 5000 && !feed.finished(); ++i) {
    feed.drain_into(history, 1e9);
    std::this_thread::sleep_for(1ms);
  }
  feed.stop();
  EXPECT_EQ(covered, scans);
  EXPECT_EQ(feed.stats().samples.load(), 20001U);  // one per frame, the first (the baseline) included
  std::filesystem::remove(log);
}

TEST(CanFeed, AMissingLogOrSignalIsNamed) {
  config::Config c = test::wheel_config("/nonexistent/can.log");
  EXPECT_THROW(CanFeed{c}, adit::InputError);
  c = test::wheel_config(test::straight_drive_log(1.0, "wheel-feed"));
  c.wheel_odometry.right_signal = "nope";
  try {
    CanFeed feed(c);
    ADD_FAILURE() << "no error";
  } catch (const adit::InputError& e) {
    EXPECT_EQ(e.key(), "wheel_odometry.right_signal");
  }
}

TEST(CanFeed, HandsOverTheAccelerometerInBodyAxesWithTheWheels) {
  // The wheels at 1 m/s and, after each wheel frame, an accelerometer frame
  // (0x310: x, y, z as int16 in mm/s²) reading (0.1, -0.2, 9.8) m/s² in its
  // own axes, mounted turned 90° left about z (imu.rpy_deg [0, 0, 90]).
  const std::filesystem::path log = test::straight_drive_log(3.0, "wheel-feed-imu", true);
  config::Config c = test::wheel_config(log);
  test::add_accelerometer(c);
  c.imu.rpy_deg = {0.0, 0.0, 90.0};
  CanFeed feed(c);
  feed.start({});
  slam::WheelHistory wheels(8192);
  slam::ImuHistory imu(8192);
  for (int i = 0; i < 2000 && !feed.finished(); ++i) {
    std::this_thread::sleep_for(1ms);
    feed.drain_into(wheels, 1e9, &imu);
  }
  feed.drain_into(wheels, 1e9, &imu);
  feed.stop();
  EXPECT_EQ(feed.stats().imu_samples.load(), 301U);
  const auto f = imu.mean(1001.0, 1001.1);
  ASSERT_TRUE(f.has_value());
  // The IMU's x is the body's y, its y the body's -x.
  EXPECT_NEAR(f->x(), 0.2, 1e-9);
  EXPECT_NEAR(f->y(), 0.1, 1e-9);
  EXPECT_NEAR(f->z(), 9.8, 1e-9);
  const auto a = wheels.acceleration(1001.0, 1001.1);
  ASSERT_TRUE(a.has_value());
  EXPECT_NEAR(a->norm(), 0.0, 1e-6) << "steady 1 m/s";
  std::filesystem::remove(log);

  c.imu.accel_y_signal = "nope";
  try {
    CanFeed named(c);
    ADD_FAILURE() << "no error";
  } catch (const adit::InputError& e) {
    EXPECT_EQ(e.key(), "imu.accel_y_signal");
  }
}

// Drains a replayed feed to its end through the ImuSource interface.
void catch_up_to_end(CanFeed& feed) {
  for (int i = 0; i < 5000 && !feed.finished(); ++i) {
    feed.catch_up(1e9, {});
    std::this_thread::sleep_for(1ms);
  }
  feed.catch_up(1e9, {});
  feed.stop();
}

TEST(CanFeed, AnImuAloneOnTheBusPairsItsGyroscopeWithItsAccelerometerInBodyAxes) {
  const std::filesystem::path log = test::imu_only_log(3.0, "imu-only", [](int, test::ImuFrames&) {});
  config::Config c = test::imu_only_config(log);
  c.imu.rpy_deg = {0.0, 0.0, 90.0};  // the IMU's x is the body's y
  c.imu.position_m = {0.1, -0.2, 0.3};
  c.imu.time_offset_s = 0.004;
  CanFeed feed(c);
  ASSERT_FALSE(feed.has_wheels());
  ASSERT_TRUE(feed.has_imu());
  const std::filesystem::path recorded = log.string() + ".recorded";
  feed.start(recorded);
  // A replay waits for the IMU alone (no wheels to wait for) and stops at until_t.
  const std::function<bool()> idle = [] { return true; };
  feed.catch_up(1001.0, idle);
  EXPECT_GE(feed.history().latest(), 1001.0);
  EXPECT_LT(feed.history().latest(), 1001.5) << "a replay hands over what the scan needs, not the whole log";
  catch_up_to_end(feed);
  const ImuStats& s = feed.imu_stats();
  EXPECT_EQ(s.packets.load(), 602U);
  EXPECT_EQ(s.samples.load(), 301U);
  EXPECT_EQ(s.gyro_samples.load(), 301U);
  EXPECT_NEAR(s.rate_hz.load(), 100.0, 0.5);
  EXPECT_EQ(describe_problems(s, "can"), "");
  EXPECT_DOUBLE_EQ(s.time_offset_s.load(), 0.004);
  // The session's candump recording carries the IMU's frames, both kinds.
  EXPECT_EQ(feed.stats().recorded.load(), 602U);
  std::ifstream recording(recorded);
  std::size_t accel_frames = 0;
  std::size_t gyro_frames = 0;
  for (std::string line; std::getline(recording, line);) {
    accel_frames += line.find(" 190#") != std::string::npos ? 1 : 0;
    gyro_frames += line.find(" 191#") != std::string::npos ? 1 : 0;
  }
  EXPECT_EQ(accel_frames, 301U);
  EXPECT_EQ(gyro_frames, 301U);
  std::filesystem::remove(recorded);
  // The lever arm is carried, not applied.
  EXPECT_EQ(feed.mounting().position_m, Eigen::Vector3d(0.1, -0.2, 0.3));
  const slam::ImuHistory& h = feed.history();
  // Stamped at the accelerometer frame, the offset removed.
  EXPECT_NEAR(h.latest(), 1003.0 - 0.004, 1e-6);
  const auto f = h.mean(1001.0, 1001.5);
  ASSERT_TRUE(f.has_value());
  EXPECT_NEAR(f->x(), 0.2, 0.003);   // -(IMU y)
  EXPECT_NEAR(f->y(), 0.1, 0.007);   // IMU x
  EXPECT_NEAR(f->z(), 9.8, 0.005);
  // The gyroscope turns with the same mounting (slam::ImuHistory gives means
  // of the specific force only): IMU (0.01, -0.02, 0.5) rad/s is body (0.02, 0.01, 0.5).
  EXPECT_TRUE(feed.mounting().rotation.isApprox(Eigen::Matrix3d(
      Eigen::AngleAxisd(0.5 * 3.141592653589793, Eigen::Vector3d::UnitZ()))));
  std::filesystem::remove(log);
}

TEST(CanFeed, ImuGapsSaturationStuckAxesTimeGoingBackAndLoneFramesAreCountedByName) {
  const std::filesystem::path log = test::imu_only_log(5.0, "imu-bad", [](int i, test::ImuFrames& f) {
    if (i >= 100 && i < 150) f.skip = true;          // a gap of 0.5 s
    if (i == 200) f.accel[0] = 32767;                // ax at the int16 limit
    if (i == 300) f.t = 1000.0 + 0.01 * 298;         // time going back
    if (i == 350) f.with_gyro = false;               // an accelerometer frame without its gyroscope
    if (i >= 400) f.gyro[2] = 2500;                  // gz stuck from here on (100 readings to the end)
  });
  CanFeed feed(test::imu_only_config(log));
  feed.start({});
  catch_up_to_end(feed);
  const ImuStats& s = feed.imu_stats();
  EXPECT_EQ(s.count(ImuProblem::gap), 1U);
  EXPECT_NEAR(s.longest_gap_s.load(), 0.51, 1e-6);
  EXPECT_EQ(s.count(ImuProblem::saturated), 1U);
  EXPECT_EQ(s.count(ImuProblem::time_back), 1U);
  EXPECT_EQ(s.count(ImuProblem::unpaired), 1U);
  EXPECT_EQ(s.count(ImuProblem::stuck_axis), 1U);
  EXPECT_EQ(s.last_problem_axis.load(), 5) << "the stuck axis is gz";
  // Kept: everything but the skipped, the one back in time; the lone accelerometer frame without gyro.
  EXPECT_EQ(s.samples.load(), 501U - 50U - 1U);
  EXPECT_EQ(s.gyro_samples.load(), s.samples.load() - 1U);
  EXPECT_NEAR(s.rate_hz.load(), 100.0, 1.0) << "the gap is left out of the rate";
  const std::string text = describe_problems(s, "can");
  EXPECT_NE(text.find("1 gap (longest 0.510 s)"), std::string::npos) << text;
  EXPECT_NE(text.find("1 saturated"), std::string::npos) << text;
  EXPECT_NE(text.find("1 time going back"), std::string::npos) << text;
  EXPECT_NE(text.find("last: stuck axis at axis gz at frame"), std::string::npos) << text;
  std::filesystem::remove(log);
}

// A bus that went bus-off for half a second (a loose connector, a babbling
// node), as candump -L logs it with error frames: linux/can/error.h's
// CAN_ERR_BUSOFF (0x40) class, then CAN_ERR_RESTARTED (0x100) when the
// controller is back. The feed counts both, says the bus is ok again, and the
// wheels go on after the gap.
TEST(CanFeed, BusOffAndItsRecoveryAreCountedFromTheErrorFrames) {
  const std::filesystem::path log = test::binary_dir() / fmt::format("bus-off-{}.log", ::getpid());
  {
    std::ofstream out(log);
    for (int i = 0; i <= 300; ++i) {
      const double t = 1000.0 + 0.01 * i;
      if (i == 100) out << fmt::format("({:.6f}) can0 20000040#0000000000000000\n", t);  // bus-off
      if (i == 150) out << fmt::format("({:.6f}) can0 20000100#0000000000000000\n", t);  // restarted
      if (i >= 100 && i < 150) continue;  // nothing on the bus meanwhile
      out << fmt::format("({:.6f}) can0 300#E803E803\n", t);
    }
  }
  CanFeed feed(test::wheel_config(log));
  feed.start({});
  slam::WheelHistory history(8192);
  for (int i = 0; i < 5000 && !feed.finished(); ++i) {
    feed.drain_into(history, 1e9);
    std::this_thread::sleep_for(1ms);
  }
  feed.drain_into(history, 1e9);
  feed.stop();
  const CanFeedStats& s = feed.stats();
  EXPECT_EQ(s.error_frames.load(), 2U);
  EXPECT_EQ(s.bus_off.load(), 1U);
  EXPECT_EQ(s.recoveries.load(), 1U);
  EXPECT_EQ(s.bus_state.load(), static_cast<int>(drivers::can::BusState::ok));
  EXPECT_EQ(s.samples.load(), 251U) << "every data frame, none of the error frames";
  EXPECT_NEAR(history.latest(), 1003.0, 1e-6) << "the wheels go on after the bus is back";
  std::filesystem::remove(log);
}

TEST(CanImuPairing, PairsEitherOrderWithinItsWindowAndReportsLoneFrames) {
  CanImuPairing pairing(true);
  const Eigen::Vector3d f(0, 0, 9.8);
  const Eigen::Vector3d w(0.1, 0, 0);
  // Gyroscope first, then its accelerometer 1 ms later.
  EXPECT_FALSE(pairing.add_gyro(1.000, w).reading);
  auto r = pairing.add_accel(1.001, f);
  ASSERT_TRUE(r.reading);
  EXPECT_TRUE(r.reading->has_gyro);
  EXPECT_EQ(r.reading->t, 1.001);
  EXPECT_EQ(r.reading->angular_rate, w);
  // An accelerometer whose gyroscope never comes is handed on alone when the next one arrives.
  EXPECT_FALSE(pairing.add_accel(1.010, f, 0x1).reading);
  r = pairing.add_accel(1.020, f);
  ASSERT_TRUE(r.reading);
  EXPECT_TRUE(r.accel_alone);
  EXPECT_FALSE(r.reading->has_gyro);
  EXPECT_EQ(r.reading->t, 1.010);
  EXPECT_EQ(r.saturated_axes, 0x1U);
  // A gyroscope 10 ms from the pending accelerometer: the accelerometer goes alone, the gyroscope waits.
  r = pairing.add_gyro(1.030, w, 0x4);
  ASSERT_TRUE(r.reading);
  EXPECT_TRUE(r.accel_alone);
  // Another gyroscope: the first had no accelerometer and is dropped.
  r = pairing.add_gyro(1.040, w);
  EXPECT_TRUE(r.gyro_dropped);
  EXPECT_FALSE(r.reading);
  r = pairing.add_accel(1.0401, f, 0x2);
  ASSERT_TRUE(r.reading);
  EXPECT_EQ(r.saturated_axes, 0x2U);
  // Without a gyroscope every accelerometer frame is a reading at once.
  CanImuPairing alone(false);
  r = alone.add_accel(2.0, f);
  ASSERT_TRUE(r.reading);
  EXPECT_FALSE(r.reading->has_gyro);
  EXPECT_FALSE(alone.add_gyro(2.0, w).reading);
}

}  // namespace
}  // namespace adit::daemon
