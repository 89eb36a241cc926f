// The daemon's CAN feed: a replayed candump log decoded into wheel poses
// and accelerometer readings, handed to the odometry thread's histories
// without losing the window that the next scans need, however long the log.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <thread>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/daemon/can_feed.hpp"
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

}  // namespace
}  // namespace adit::daemon
