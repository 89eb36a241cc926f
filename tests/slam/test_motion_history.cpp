// The odometry's motion histories: wheel poses interpolated into a motion
// prior and a kinematic acceleration, accelerometer readings averaged over a
// sweep, and a capacity that drops the oldest.
#include <gtest/gtest.h>

#include <cmath>

#include "adit/slam/motion_history.hpp"

namespace adit::slam {
namespace {

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

// The wheels silent for a second (a bus-off): the odometry holds its pose
// across the gap (nothing integrated), so a prior across it would say the body
// stood still. None is given; on either side of the gap priors are as before.
TEST(WheelHistory, GivesNoPriorAcrossTheWheelsSilence) {
  WheelHistory history(16);
  for (int i = 0; i <= 4; ++i) history.push({0.1 * i, {0.1 * i, 0.0, 0.0}, 0.1 * i});
  // Silent from 0.4 s to 1.4 s; the pose resumes where it was held.
  for (int i = 0; i <= 4; ++i) history.push({1.4 + 0.1 * i, {0.4 + 0.1 * i, 0.0, 0.0}, 0.4 + 0.1 * i, i == 0});
  EXPECT_TRUE(history.prior(0.1, 0.4).has_value());
  EXPECT_FALSE(history.prior(0.3, 0.9).has_value()) << "into the silence";
  EXPECT_FALSE(history.prior(0.3, 1.5).has_value()) << "across it";
  EXPECT_FALSE(history.prior(0.9, 1.5).has_value()) << "out of it";
  const auto after = history.prior(1.4, 1.7);
  ASSERT_TRUE(after.has_value());
  EXPECT_NEAR(after->delta.translation().x(), 0.3, 1e-12);
}

// A wheel held for slip from 1.0 s to 1.3 s (samples 1.1-1.3 held): its
// travel is a guess (in a turn's onset the held wheel assumes the turn rate
// from before, decision 051), so no prior or acceleration covers it; before
// and after, they are as before.
TEST(WheelHistory, GivesNoPriorOverAWheelHeldForSlip) {
  WheelHistory history(64);
  for (int i = 0; i <= 20; ++i) {
    const double t = 0.1 * i;
    WheelSample s{t, {t, 0.0, 0.0}, t};
    s.held = i >= 11 && i <= 13;
    history.push(s);
  }
  EXPECT_TRUE(history.prior(0.5, 1.0).has_value()) << "before the slip";
  EXPECT_FALSE(history.held(0.5, 1.0));
  EXPECT_FALSE(history.prior(0.95, 1.05).has_value()) << "into it (sample 1.1 covers (1.0, 1.1])";
  EXPECT_TRUE(history.held(0.95, 1.05));
  EXPECT_FALSE(history.prior(1.2, 1.6).has_value()) << "out of it";
  EXPECT_FALSE(history.prior(0.5, 1.6).has_value()) << "across it";
  EXPECT_TRUE(history.prior(1.3, 1.8).has_value()) << "after it (sample 1.4 covers (1.3, 1.4])";
  EXPECT_FALSE(history.held(1.3, 1.8));
  EXPECT_TRUE(history.acceleration(0.3, 0.6).has_value());
  EXPECT_FALSE(history.acceleration(1.0, 1.2).has_value());
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

TEST(ImuHistory, CopiesTheReadingsThatCoverAnInterval) {
  ImuHistory history(16);
  for (int k = 0; k < 20; ++k) history.push({0.01 * k, Eigen::Vector3d::Zero()});  // 0.04 .. 0.19 kept
  std::vector<ImuSample> out;
  out.reserve(16);
  history.copy_covering(0.085, 0.125, out);
  ASSERT_EQ(out.size(), 6U);  // 0.08 .. 0.13
  EXPECT_DOUBLE_EQ(out.front().t, 0.08);
  EXPECT_DOUBLE_EQ(out.back().t, 0.13);
  history.copy_covering(0.0, 0.05, out);
  ASSERT_EQ(out.size(), 2U) << "from the oldest kept";
  EXPECT_DOUBLE_EQ(out.front().t, 0.04);
  history.copy_covering(0.18, 0.5, out);
  ASSERT_EQ(out.size(), 2U) << "to the newest";
  EXPECT_DOUBLE_EQ(out.back().t, 0.19);
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

}  // namespace
}  // namespace adit::slam
