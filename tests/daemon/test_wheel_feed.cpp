// The daemon's wheel feed: a replayed candump log decoded into wheel poses
// (and accelerometer readings), handed to the odometry thread's histories
// without losing the window that the next scans need, however long the log.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <thread>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/daemon/wheel_feed.hpp"
#include "shared_data.hpp"

namespace adit::daemon {
namespace {

using namespace std::chrono_literals;

// Both wheels at 1 m/s for `seconds` (rim speed in mm/s as uint16, 100 Hz).
std::filesystem::path straight_drive_log(double seconds) {
  const std::filesystem::path file = test::binary_dir() / fmt::format("wheel-feed-{}.log", ::getpid());
  std::ofstream out(file);
  for (int i = 0; i <= static_cast<int>(seconds * 100); ++i)
    out << fmt::format("({:.6f}) can0 300#E803E803\n", 1000.0 + 0.01 * i);  // 1000 mm/s, little-endian
  return file;
}

config::Config wheel_config(const std::filesystem::path& log) {
  config::Config c;
  c.can.enabled = true;
  c.can.source = config::CanSource::candump;
  c.can.log = log.string();
  config::CanSignal left;
  left.name = "left";
  left.id = 0x300;
  left.start_bit = 0;
  left.length = 16;
  left.factor = 0.001;
  left.unit = "m/s";
  config::CanSignal right = left;
  right.name = "right";
  right.start_bit = 16;
  c.can.signals = {left, right};
  c.wheel_odometry.enabled = true;
  c.wheel_odometry.left_signal = "left";
  c.wheel_odometry.right_signal = "right";
  c.wheel_odometry.quantity = config::WheelQuantity::speed;
  return c;
}

TEST(WheelHistory, InterpolatesTheMotionBetweenTwoTimesAndKeepsItsCapacity) {
  WheelHistory history(4);
  EXPECT_FALSE(history.prior(0.0, 1.0).has_value());
  for (int i = 0; i < 6; ++i) history.push({static_cast<double>(i), {static_cast<double>(i), 0.0, 0.0}, 1.0 * i});
  EXPECT_DOUBLE_EQ(history.latest(), 5.0);
  EXPECT_FALSE(history.prior(1.0, 3.0).has_value()) << "t = 1 fell out of the 4 samples kept";
  const auto prior = history.prior(2.5, 4.25);
  ASSERT_TRUE(prior.has_value());
  EXPECT_NEAR(prior->delta.translation().x(), 1.75, 1e-12);
  EXPECT_FALSE(history.prior(4.0, 5.5).has_value()) << "beyond the newest sample";
}

TEST(WheelFeed, AReplayedLogLongerThanTheHistoryStillCoversEveryScan) {
  // 200 s at 100 Hz: 20 000 samples, more than the hand-off (1024) and the history (8192) hold.
  const std::filesystem::path log = straight_drive_log(200.0);
  WheelFeed feed(wheel_config(log));
  ASSERT_TRUE(feed.replay());
  feed.start({});
  WheelHistory history(8192);
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
  feed.stop();
  EXPECT_EQ(covered, scans);
  EXPECT_EQ(feed.stats().samples.load(), 20001U);  // one per frame, the first (the baseline) included
  std::filesystem::remove(log);
}

TEST(WheelFeed, AMissingLogOrSignalIsNamed) {
  config::Config c = wheel_config("/nonexistent/can.log");
  EXPECT_THROW(WheelFeed{c}, adit::InputError);
  c = wheel_config(straight_drive_log(1.0));
  c.wheel_odometry.right_signal = "nope";
  try {
    WheelFeed feed(c);
    ADD_FAILURE() << "no error";
  } catch (const adit::InputError& e) {
    EXPECT_EQ(e.key(), "wheel_odometry.right_signal");
  }
}

TEST(ImuHistory, AveragesTheReadingsJoinedByLinesOverAnyInterval) {
  ImuHistory history(64);
  // f_x = 2t: readings every 10 ms, 3 ms after each 10 ms mark (as a bus delays them).
  for (int k = 0; k < 40; ++k) {
    const double t = 0.003 + 0.01 * k;
    history.push({t, Eigen::Vector3d(2.0 * t, 0.0, 9.8)});
  }
  // The mean of 2t over [0.1, 0.2] is 0.3, whatever the readings' phase; the
  // plain mean of the ten readings inside would be 0.306 (shifted 3 ms).
  const auto mean = history.mean(0.1, 0.2);
  ASSERT_TRUE(mean.has_value());
  EXPECT_NEAR(mean->x(), 0.3, 1e-12);
  EXPECT_NEAR(mean->z(), 9.8, 1e-12);
  EXPECT_FALSE(history.mean(0.35, 0.45).has_value()) << "no reading after the interval";
  EXPECT_FALSE(history.mean(0.1, 0.115).has_value()) << "one reading inside, three asked for";
  EXPECT_TRUE(history.mean(0.1, 0.115, 1).has_value());
}

TEST(WheelHistory, GivesTheBodysAccelerationAlongAndAcrossItsHeading) {
  // Speeding up along x at 0.5 m/s² from 1 m/s: a forward acceleration, nothing sideways.
  WheelHistory straight(512);
  for (int k = 0; k <= 300; ++k) {
    const double t = 0.01 * k;
    const double x = t + 0.25 * t * t;
    straight.push({t, {x, 0.0, 0.0}, x});
  }
  const auto a = straight.acceleration(1.0, 1.1);
  ASSERT_TRUE(a.has_value());
  EXPECT_NEAR(a->x(), 0.5, 1e-9);
  EXPECT_NEAR(a->y(), 0.0, 1e-12);
  // A left turn on a 2 m circle at 1 m/s: 0.5 m/s² towards the centre (left), none along.
  WheelHistory circle(512);
  for (int k = 0; k <= 300; ++k) {
    const double t = 0.01 * k;
    const double angle = t / 2.0;
    circle.push({t, {2.0 * std::sin(angle), 2.0 - 2.0 * std::cos(angle), angle}, t});
  }
  const auto c = circle.acceleration(1.0, 1.1);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->x(), 0.0, 1e-6);
  EXPECT_NEAR(c->y(), 0.5, 1e-3);  // the chord speed over ±50 ms is 1 m/s to 1e-4
  EXPECT_FALSE(circle.acceleration(2.9, 3.0).has_value()) << "the speed at 3.0 needs samples to 3.05";
}

TEST(WheelFeed, HandsOverTheAccelerometerInBodyAxesWithTheWheels) {
  // The wheels at 1 m/s and, after each wheel frame, an accelerometer frame
  // (0x310: x, y, z as int16 in mm/s²) reading (0.1, -0.2, 9.8) m/s² in its
  // own axes, mounted turned 90° left about z (imu.rpy_deg [0, 0, 90]).
  const std::filesystem::path log = test::binary_dir() / fmt::format("wheel-feed-imu-{}.log", ::getpid());
  {
    std::ofstream out(log);
    for (int i = 0; i <= 300; ++i) {
      out << fmt::format("({:.6f}) can0 300#E803E803\n", 1000.0 + 0.01 * i);
      out << fmt::format("({:.6f}) can0 310#640038FF4826\n", 1000.0 + 0.01 * i + 0.0003);
    }
  }
  config::Config c = wheel_config(log);
  for (int axis = 0; axis < 3; ++axis) {
    config::CanSignal s;
    s.name = fmt::format("accel_{}", "xyz"[axis]);
    s.id = 0x310;
    s.start_bit = 16 * axis;
    s.length = 16;
    s.value_type = config::ValueType::signed_int;
    s.factor = 0.001;
    s.unit = "m/s2";
    c.can.signals.push_back(s);
  }
  c.imu.enabled = true;
  c.imu.accel_x_signal = "accel_x";
  c.imu.accel_y_signal = "accel_y";
  c.imu.accel_z_signal = "accel_z";
  c.imu.rpy_deg = {0.0, 0.0, 90.0};
  WheelFeed feed(c);
  feed.start({});
  WheelHistory wheels(8192);
  ImuHistory imu(8192);
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
    WheelFeed named(c);
    ADD_FAILURE() << "no error";
  } catch (const adit::InputError& e) {
    EXPECT_EQ(e.key(), "imu.accel_y_signal");
  }
}

}  // namespace
}  // namespace adit::daemon
