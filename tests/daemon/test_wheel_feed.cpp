// The daemon's wheel feed: a replayed candump log decoded into wheel poses,
// handed to the odometry thread's history without losing the window that the
// next scans need, however long the log.
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

}  // namespace
}  // namespace adit::daemon
