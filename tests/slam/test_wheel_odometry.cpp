#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "adit/slam/wheel_odometry.hpp"

namespace slam = adit::slam;

namespace {
slam::WheelGeometry geometry() {
  slam::WheelGeometry g;
  g.left_radius = 0.1;
  g.right_radius = 0.1;
  g.track_width = 0.5;
  g.counts_per_revolution = 1000;
  g.counter_bits = 16;
  return g;
}
// The simulated mine robot's encoders (sim/src/wheel_encoders.cpp): 16384
// counts per revolution on 0.1651 m wheels 0.555 m apart, 32-bit counters;
// a wheel slips beyond 4 m/s² (the simulator's session.yaml).
struct RobotEncoders {
  static slam::WheelGeometry geometry() {
    slam::WheelGeometry g;
    g.left_radius = g.right_radius = 0.1651;
    g.track_width = 0.555;
    g.counts_per_revolution = 16384;
    g.counter_bits = 32;
    return g;
  }
  static slam::WheelLimits limits() {
    slam::WheelLimits l;
    l.max_acceleration = 4.0;
    return l;
  }
  // The counters of wheels whose rims have turned left_m and right_m, read at t.
  slam::WheelStep read(double t, double left_m, double right_m) {
    const double counts_per_m = 16384 / (2.0 * std::numbers::pi * 0.1651);
    return odometry.add_counts(t, static_cast<std::uint64_t>(std::llround(left_m * counts_per_m)),
                               static_cast<std::uint64_t>(std::llround(right_m * counts_per_m)));
  }
  slam::WheelOdometry odometry{geometry(), {}, limits()};
};

}  // namespace

TEST(WheelOdometry, StraightLineAndCovarianceGrowsWithDistance) {
  slam::WheelOdometry odo(geometry());
  EXPECT_EQ(odo.add_speeds(0.0, 1.0, 1.0), slam::WheelStep::first);
  double previous_variance = 0.0;
  for (int i = 1; i <= 100; ++i) {
    ASSERT_EQ(odo.add_speeds(i * 0.01, 1.0, 1.0), slam::WheelStep::integrated);
    const double variance = odo.covariance().trace();
    EXPECT_GT(variance, previous_variance);
    previous_variance = variance;
  }
  EXPECT_NEAR(odo.pose().x, 1.0, 1e-12);
  EXPECT_NEAR(odo.pose().y, 0.0, 1e-12);
  EXPECT_NEAR(odo.distance(), 1.0, 1e-12);
  // Lateral uncertainty appears only through heading uncertainty.
  EXPECT_GT(odo.covariance()(1, 1), 0.0);
}

TEST(WheelOdometry, CircleClosesAndTurningAddsHeadingVariance) {
  const slam::WheelGeometry g = geometry();
  slam::WheelOdometry odo(g);
  // Radius 1 m: v_l = w (R - b/2), v_r = w (R + b/2), with w = 1 rad/s for 2 pi s.
  const double w = 1.0;
  const int steps = 6283;
  const double dt = 2 * std::numbers::pi / steps;
  for (int i = 0; i <= steps; ++i) odo.add_speeds(i * dt, w * (1 - 0.25), w * (1 + 0.25));
  EXPECT_NEAR(odo.pose().x, 0.0, 1e-6);
  EXPECT_NEAR(odo.pose().y, 0.0, 1e-6);
  EXPECT_NEAR(odo.pose().theta, 0.0, 1e-6);

  // Same wheel travel in total, so Siegwart's wheel terms are equal; the
  // turning term makes the turning run's heading less certain.
  slam::WheelOdometry straight(g);
  slam::WheelOdometry turning(g);
  for (int i = 0; i <= 100; ++i) {
    straight.add_speeds(i * 0.01, 1.0, 1.0);
    turning.add_speeds(i * 0.01, 0.5, 1.5);  // same centre distance
  }
  EXPECT_NEAR(straight.distance(), turning.distance(), 1e-12);
  EXPECT_GT(turning.covariance()(2, 2), straight.covariance()(2, 2));
}

TEST(WheelOdometry, SkidFactorWidensTheEffectiveTrack) {
  slam::WheelGeometry g = geometry();
  g.skid_factor = 2.0;
  slam::WheelOdometry odo(g);
  for (int i = 0; i <= 10; ++i) odo.add_speeds(i * 0.1, -0.5, 0.5);
  EXPECT_NEAR(odo.pose().theta, 1.0 / (0.5 * 2.0), 1e-12);
}

TEST(WheelOdometry, CounterDeltaWraps) {
  EXPECT_EQ(slam::counter_delta(65530, 5, 16), 11);
  EXPECT_EQ(slam::counter_delta(5, 65530, 16), -11);
  EXPECT_EQ(slam::counter_delta(0xFFFFFFFFFFFFFFFFULL, 1, 64), 2);
  EXPECT_EQ(slam::counter_delta(100, 90, 32), -10);
  EXPECT_EQ(slam::counter_delta(0, 32767, 16), 32767);
  EXPECT_EQ(slam::counter_delta(0, 32768, 16), -32768);
}

TEST(WheelOdometry, EncoderCountsAcrossWrapIntegrateExactly) {
  slam::WheelOdometry odo(geometry());
  // 1 revolution = 1000 counts = 0.2 pi m; start near the 16-bit top.
  std::uint64_t c = 65000;
  odo.add_counts(0.0, c, c);
  for (int i = 1; i <= 20; ++i) {
    c = (c + 100) & 0xFFFF;
    ASSERT_EQ(odo.add_counts(i * 0.1, c, c), slam::WheelStep::integrated);
  }
  EXPECT_NEAR(odo.pose().x, 2.0 * 0.2 * std::numbers::pi, 1e-9);
  EXPECT_EQ(odo.stats().counter_wraps, 2U);  // left and right wrapped once each
}

TEST(WheelOdometry, CounterGlitchIsRejectedAndTheNextGoodReadingCoversTheInterval) {
  slam::WheelOdometry odo(geometry());
  odo.add_counts(0.0, 0, 0);
  odo.add_counts(0.1, 100, 100);
  // A corrupted reading: 30000 counts in 0.1 s is 188 m/s.
  EXPECT_EQ(odo.add_counts(0.2, 30100, 200), slam::WheelStep::impossible);
  EXPECT_EQ(odo.add_counts(0.3, 300, 300), slam::WheelStep::integrated);
  EXPECT_NEAR(odo.pose().x, 300 * 0.2 * std::numbers::pi / 1000, 1e-9);
  EXPECT_NEAR(odo.pose().theta, 0.0, 1e-12);
  EXPECT_EQ(odo.stats().impossible, 1U);
}

TEST(WheelOdometry, SpeedSpikeIsHeldNotIntegrated) {
  slam::WheelOdometry odo(geometry());
  odo.add_speeds(0.0, 1.0, 1.0);
  odo.add_speeds(0.1, 1.0, 1.0);
  EXPECT_EQ(odo.add_speeds(0.2, 9.0, 1.0), slam::WheelStep::slip);  // 80 m/s^2 on one wheel
  EXPECT_EQ(odo.add_speeds(0.3, 1.0, 1.0), slam::WheelStep::integrated);
  EXPECT_NEAR(odo.pose().x, 0.3, 1e-9);
  EXPECT_NEAR(odo.pose().theta, 0.0, 1e-12);
  EXPECT_EQ(odo.add_speeds(0.4, 100.0, 1.0), slam::WheelStep::impossible);
  EXPECT_EQ(odo.add_speeds(0.5, NAN, 1.0), slam::WheelStep::impossible);
  EXPECT_EQ(odo.stats().slips, 1U);
  EXPECT_EQ(odo.stats().impossible, 2U);
}

TEST(WheelOdometry, RealStepChangeIsAcceptedAfterTheLongestSlip) {
  slam::WheelLimits limits;
  limits.max_slip_duration = 0.035;
  slam::WheelOdometry odo(geometry(), {}, limits);
  odo.add_speeds(0.0, 0.0, 0.0);
  odo.add_speeds(0.01, 0.0, 0.0);
  for (int i = 2; i <= 4; ++i) EXPECT_EQ(odo.add_speeds(i * 0.01, 5.0, 5.0), slam::WheelStep::slip);
  EXPECT_EQ(odo.add_speeds(0.05, 5.0, 5.0), slam::WheelStep::rebaselined);
  EXPECT_EQ(odo.add_speeds(0.06, 5.0, 5.0), slam::WheelStep::integrated);
  EXPECT_EQ(odo.stats().rebaselined, 1U);
  EXPECT_EQ(odo.stats().slip_episodes, 2U);  // one per wheel
}

TEST(WheelOdometry, RepeatedImpossibleReadingsBecomeTheNewBaseline) {
  slam::WheelLimits limits;
  limits.max_rejected = 3;
  slam::WheelOdometry odo(geometry(), {}, limits);
  odo.add_speeds(0.0, 1.0, 1.0);
  for (int i = 1; i <= 3; ++i) EXPECT_EQ(odo.add_speeds(i * 0.01, 20.0, 1.0), slam::WheelStep::impossible);
  EXPECT_EQ(odo.add_speeds(0.04, 20.0, 1.0), slam::WheelStep::rebaselined);
  EXPECT_EQ(odo.stats().impossible, 4U);
}

// The simulator's slip (sim/src/wheel_encoders.cpp): one wheel's encoder runs
// 30 % fast for 0.3 s while the robot drives straight at 1 m/s. Counts at
// 100 Hz, 16384 per revolution. Without slip handling the false turn is
// 0.3 * 1 m/s * 0.3 s / 0.555 m = 9.3 degrees.
TEST(WheelOdometry, ASpinningWheelsCountsAreReplacedByItsTrustedSpeedUntilItGripsAgain) {
  RobotEncoders encoders;
  const slam::WheelOdometry& odo = encoders.odometry;
  double left = 0.0, right = 0.0;  // metres the wheels turned (rim)
  int slips = 0;
  for (int k = 0; k <= 300; ++k) {  // 3 s
    const double t = k * 0.01;
    const bool spinning = t > 1.0 + 1e-9 && t <= 1.3 + 1e-9;
    if (k > 0) {
      left += 0.01 * 1.0 * (spinning ? 1.3 : 1.0);
      right += 0.01 * 1.0;
    }
    const auto step = encoders.read(t, left, right);
    ASSERT_NE(step, slam::WheelStep::rebaselined) << t;
    if (step == slam::WheelStep::slip) ++slips;
  }
  EXPECT_EQ(slips, 30);  // the whole spin, and only it
  EXPECT_EQ(odo.stats().slip_episodes, 1U);
  EXPECT_NEAR(odo.pose().theta * 180.0 / std::numbers::pi, 0.0, 0.05);  // 9.3° without slip handling
  EXPECT_NEAR(odo.pose().x, 3.0, 0.002);
  EXPECT_NEAR(odo.pose().y, 0.0, 0.002);
}

// A slip that begins halfway through a 10 ms interval shows as two steps of
// 0.15 m/s, each within the bound over one interval (4 m/s² * 0.02 s plus the
// counts' noise, 0.19 m/s at 1 m/s), but not together.
TEST(WheelOdometry, ASlipThatStartsWithinAnIntervalIsStillCaught) {
  RobotEncoders encoders;
  const slam::WheelOdometry& odo = encoders.odometry;
  double left = 0.0, right = 0.0;
  for (int k = 0; k <= 300; ++k) {
    const double t = k * 0.01;
    if (k > 0) {
      const double gain = k == 101 ? 1.15 : (k > 101 && k <= 130) ? 1.3 : k == 131 ? 1.15 : 1.0;
      left += 0.01 * gain;
      right += 0.01;
    }
    encoders.read(t, left, right);
  }
  EXPECT_EQ(odo.stats().slip_episodes, 1U);
  // The half-steps at its two ends get through (0.15 * 1 m/s * 10 ms each,
  // 0.31° in all); a slip that is missed turns the robot by 9.3°.
  EXPECT_NEAR(odo.pose().theta * 180.0 / std::numbers::pi, 0.0, 0.5);
}

// The robot speeds up while the left wheel spins: the held wheel follows the
// other one (the turn rate from before the slip), so the slip ends when the
// spin does, and the distance is right. Held at its own speed from before the
// slip, it would stay 'slipping' after the spin ended, and the simulated
// drift lost accuracy that way (docs/decisions/005-wheel-slip-held.md).
TEST(WheelOdometry, AWheelHeldForSlipFollowsTheOtherWheelsAcceleration) {
  RobotEncoders encoders;
  const slam::WheelOdometry& odo = encoders.odometry;
  double left = 0.0, right = 0.0, x = 0.0;
  int slips = 0;
  for (int k = 0; k <= 200; ++k) {
    const double t = k * 0.01;
    const double v = 0.5 + 0.5 * t;  // 0.5 m/s², 0.5 -> 1.5 m/s
    if (k > 0) {
      const bool spinning = k > 100 && k <= 130;
      left += 0.01 * v * (spinning ? 1.3 : 1.0);
      right += 0.01 * v;
      x += 0.01 * v;
    }
    if (encoders.read(t, left, right) == slam::WheelStep::slip) ++slips;
  }
  EXPECT_EQ(slips, 30);
  EXPECT_EQ(odo.stats().slip_episodes, 1U);
  EXPECT_NEAR(odo.pose().theta * 180.0 / std::numbers::pi, 0.0, 0.05);
  EXPECT_NEAR(odo.pose().x, x, 0.002);
}

// The robot brakes while the left wheel spins 30 % fast for 0.3 s (the
// simulator's slip). The spin's excess shrinks with the speed, so the slip
// may look over before the spin is (the excess under the bound); the spin's
// real end, a drop of that excess, then looks like a new slip, judged against
// speeds from within the spin. Held so, the wheel made a phantom turn and
// kept the scans without a wheel prior for max_slip_duration: the simulated
// building robot, seed 11, overshot a stop by 1.1 m
// (docs/decisions/079-a-slip-ends-where-its-traction-says.md). Swept over
// braking rates and the speed at which the spin ends, none held after it.
TEST(WheelOdometry, ASpinThatEndsWhileBrakingEndsItsSlip) {
  int cases = 0;
  for (const double braking : {1.5, 2.5, 3.5}) {        // m/s², under the 4 m/s² traction limit
    for (int end_cm = 30; end_cm <= 90; end_cm += 2) {  // speed when the spin ends, m/s
      const double spin_end = 2.0;
      const double v_end = 0.01 * end_cm;
      const auto speed = [&](double t) { return std::clamp(v_end + braking * (spin_end - t), 0.0, 1.5); };
      RobotEncoders encoders;
      const slam::WheelOdometry& odo = encoders.odometry;
      double left = 0.0, right = 0.0, x = 0.0;
      double last_held = 0.0;
      for (int k = 0; k <= 400; ++k) {  // 4 s: cruising, braking, stopped
        const double t = k * 0.01;
        if (k > 0) {
          const double v = speed(t - 0.005);  // the interval's mean
          const bool spinning = t > spin_end - 0.3 + 1e-9 && t <= spin_end + 1e-9;
          left += 0.01 * v * (spinning ? 1.3 : 1.0);
          right += 0.01 * v;
          x += 0.01 * v;
        }
        if (encoders.read(t, left, right) == slam::WheelStep::slip) last_held = t;
      }
      SCOPED_TRACE(::testing::Message() << "braking " << braking << " m/s², spin ends at " << v_end << " m/s");
      EXPECT_LE(last_held, spin_end + 0.02 + 1e-9);
      EXPECT_EQ(odo.stats().rebaselined, 0U);
      // Where the excess has faded under the bound (0.09 m/s + 10 % of the
      // speed) it is integrated, as any slip under the bound is (decision
      // 005): at 1.5 m/s² that is 0.1 s of it, 1.4°. The phantom turn was up to 15°.
      EXPECT_NEAR(odo.pose().theta * 180.0 / std::numbers::pi, 0.0, 1.5);
      EXPECT_NEAR(odo.pose().x, x, 0.01);
      ++cases;
    }
  }
  EXPECT_EQ(cases, 93);
}

// The same at a steady turn and a slow, legal acceleration: nothing is held.
TEST(WheelOdometry, AccelerationWithinTractionIsNeverTakenForSlip) {
  RobotEncoders encoders;
  const slam::WheelOdometry& odo = encoders.odometry;
  double left = 0.0, right = 0.0, v = 0.0;
  for (int k = 0; k <= 500; ++k) {
    const double t = k * 0.01;
    v = std::min(1.5, 0.02 * k * 1.5);  // 1.5 m/s² up to 1.5 m/s, then steady
    left += 0.01 * v * 0.8;             // turning left
    right += 0.01 * v * 1.2;
    EXPECT_NE(encoders.read(t, left, right), slam::WheelStep::slip) << t;
  }
  EXPECT_EQ(odo.stats().slip_episodes, 0U);
}

TEST(WheelOdometry, TimeBackwardsAndGapsAreNotIntegrated) {
  slam::WheelOdometry odo(geometry());
  odo.add_speeds(1.0, 1.0, 1.0);
  EXPECT_EQ(odo.add_speeds(0.5, 1.0, 1.0), slam::WheelStep::time_backwards);
  EXPECT_EQ(odo.add_speeds(1.0, 1.0, 1.0), slam::WheelStep::time_backwards);
  EXPECT_EQ(odo.add_speeds(5.0, 1.0, 1.0), slam::WheelStep::gap);
  EXPECT_EQ(odo.pose().x, 0.0);
  EXPECT_EQ(odo.add_speeds(5.1, 1.0, 1.0), slam::WheelStep::integrated);
  EXPECT_NEAR(odo.pose().x, 0.1, 1e-12);
}
