// The IMU-rate pose's hand-over between threads (daemon/imu_pose_feed.hpp):
// anchored from the odometry thread while readings arrive on another, it
// gives a pose per reading from the first anchor on (run under ThreadSanitizer in CI).

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "../slam/smooth_motion.hpp"
#include "adit/common/clock.hpp"
#include "adit/daemon/imu_pose_feed.hpp"

namespace adit::daemon {
namespace {

using slam::test::Motion;

constexpr double kRate = 200.0;

TEST(ImuPoseFeed, AnchoredFromOneThreadItGivesAPosePerReadingOnAnother) {
  const Motion m;
  const std::vector<slam::ImuSample> imu = slam::test::samples(m, 1.0, 6.0, kRate);
  std::vector<slam::InertialState> given;
  given.reserve(imu.size());
  std::vector<double> position_variance;
  position_variance.reserve(imu.size());
  ImuPoseFeed feed(slam::ImuExtrapolatorConfig{}, [&](const slam::InertialState& s, const slam::Matrix6d& covariance) {
    given.push_back(s);
    position_variance.push_back(covariance(0, 0));
  });
  std::atomic<std::size_t> read{0};
  // The odometry: a scan every 0.1 s of the readings, its state (the truth
  // here) anchored once the readings have passed the scan's end.
  std::thread odometry([&] {
    for (double scan = 1.0; scan < 5.8; scan += 0.1) {
      const auto passed = [&] {
        const std::size_t n = read.load();
        return n == imu.size() || (n > 0 && imu[n - 1].t >= scan + 0.1);
      };
      while (!passed()) std::this_thread::yield();
      feed.anchor(m.state(scan), slam::Matrix18d::Identity() * 1e-6);
    }
  });
  for (const slam::ImuSample& r : imu) {
    feed.reading(r, adit::monotonic_ns());
    read.fetch_add(1);
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  odometry.join();
  // Every reading from the first scan's end on (the first anchor may come later on a busy machine).
  EXPECT_GE(given.size(), imu.size() - 60);
  EXPECT_EQ(feed.poses(), given.size());
  EXPECT_EQ(feed.latency_ms().size(), given.size());
  double worst_m = 0.0;
  for (const slam::InertialState& s : given) worst_m = std::max(worst_m, (s.pose.translation() - m.position(s.t)).norm());
  EXPECT_LT(worst_m, 1e-3);
  for (const double ms : feed.latency_ms()) EXPECT_GE(ms, 0.0);
  // The anchor's covariance reaches each pose, grown by the readings since it.
  for (const double v : position_variance) EXPECT_GT(v, 1e-6);
}

}  // namespace
}  // namespace adit::daemon
