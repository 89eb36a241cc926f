#include "adit/slam/imu_extrapolator.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "allocation_counter.hpp"
#include "smooth_motion.hpp"

namespace adit::slam {
namespace {

using test::Motion;
using test::rotation_error_rad;
using test::samples;

constexpr double kRate = 200.0;

double position_error_m(const InertialState& s, const Motion& m) { return (s.pose.translation() - m.position(s.t)).norm(); }

TEST(ImuExtrapolator, FollowsTheBodyAtTheImuRateFromTheLatestAnchor) {
  const Motion m;
  ImuExtrapolator x(ImuExtrapolatorConfig{});
  const std::vector<ImuSample> imu = samples(m, 0.9, 1.4, kRate);
  std::size_t given = 0, before_anchor = 0;
  double worst_m = 0.0, worst_rad = 0.0;
  for (const ImuSample& r : imu) {
    if (std::abs(r.t - 1.0) < 1e-9) x.anchor(m.state(1.0));  // the scan at 1.0, registered at once
    const std::optional<InertialState> s = x.add(r);
    if (r.t < 1.0 - 1e-9) {
      before_anchor += s.has_value();
      continue;
    }
    ASSERT_TRUE(s.has_value()) << "t " << r.t;
    ++given;
    EXPECT_NEAR(s->t, r.t, 1e-12);
    worst_m = std::max(worst_m, position_error_m(*s, m));
    worst_rad = std::max(worst_rad, rotation_error_rad(s->pose.linear(), m.rotation(s->t)));
  }
  EXPECT_EQ(before_anchor, 0U) << "no pose before the first anchor";
  EXPECT_EQ(given, 81U);
  // Exact readings, 0.4 s of midpoint integration: as the filter's own propagation.
  EXPECT_LT(worst_m, 1e-3);
  EXPECT_LT(worst_rad, 1e-4);
}

// The pose's covariance is the filter's own, carried by the same error-state
// propagation (inertial_kinematics.hpp) through the readings since the
// anchor, in the body tangent of the scan-rate pose; it grows with them.
TEST(ImuExtrapolator, ThePosesCovarianceIsTheFiltersPropagatedThroughTheReadings) {
  const Motion m;
  const std::vector<ImuSample> imu = samples(m, 0.95, 1.4, kRate);
  InertialFilter filter(InertialConfig{});
  Matrix6d pose_covariance = Matrix6d::Zero();
  pose_covariance.diagonal() << 1e-4, 2e-4, 3e-4, 1e-6, 2e-6, 3e-6;
  filter.reset(m.state(1.0), pose_covariance);
  ImuExtrapolator x(ImuExtrapolatorConfig{});
  x.anchor(filter.state(), filter.covariance());
  double previous_variance = 0.0;
  std::size_t checked = 0;
  for (const ImuSample& r : imu) {
    const std::optional<InertialState> s = x.add(r);
    if (r.t < 1.0 + 1e-9) continue;
    ASSERT_TRUE(s.has_value());
    ASSERT_TRUE(filter.propagate(imu, r.t));
    Matrix6d M = Matrix6d::Identity();
    M.topLeftCorner<3, 3>() = filter.state().pose.linear().transpose();
    const Matrix6d expected = M * filter.covariance().topLeftCorner<6, 6>() * M.transpose();
    const Matrix6d given = x.pose_covariance();
    EXPECT_LT((given - expected).norm(), 1e-9 * expected.norm()) << "t " << r.t;
    const double variance = given.topLeftCorner<3, 3>().trace();
    EXPECT_GT(variance, previous_variance) << "t " << r.t;
    previous_variance = variance;
    ++checked;
  }
  EXPECT_EQ(checked, 80U);
  // 0.4 s past the scan the position is less certain than at it.
  EXPECT_GT(previous_variance, 6e-4);
}

TEST(ImuExtrapolator, ALateAnchorIsCarriedThroughTheReadingsSinceIt) {
  const Motion m;
  ImuExtrapolator x(ImuExtrapolatorConfig{});
  const std::vector<ImuSample> imu = samples(m, 0.9, 1.3, kRate);
  // A first anchor 0.2 m off; the scan at 1.0 (between readings) is
  // registered while 30 ms of readings arrive after it.
  InertialState off = m.state(0.9);
  off.pose.translation().x() += 0.2;
  x.anchor(off);
  std::size_t i = 0;
  for (; imu[i].t < 1.03 - 1e-9; ++i) ASSERT_TRUE(x.add(imu[i]).has_value());
  const std::optional<InertialState> stale = x.add(imu[i++]);
  ASSERT_TRUE(stale.has_value());
  EXPECT_GT(position_error_m(*stale, m), 0.19);
  x.anchor(m.state(1.0025));
  const std::optional<InertialState> now = x.add(imu[i]);
  ASSERT_TRUE(now.has_value());
  EXPECT_NEAR(now->t, imu[i].t, 1e-12);
  EXPECT_LT(position_error_m(*now, m), 1e-4) << "the correction reaches the next pose";
  EXPECT_LT(rotation_error_rad(now->pose.linear(), m.rotation(now->t)), 1e-5);
}

TEST(ImuExtrapolator, NothingAcrossAGapOrPastTheHorizonOrOutOfOrder) {
  const Motion m;
  ImuExtrapolatorConfig config;
  config.max_horizon_s = 0.3025;  // between two readings
  ImuExtrapolator x(config);
  x.anchor(m.state(1.0));
  std::vector<ImuSample> imu = samples(m, 1.0, 2.0, kRate);
  std::size_t i = 0;
  for (; imu[i].t <= 1.3 + 1e-9; ++i) EXPECT_TRUE(x.add(imu[i]).has_value()) << imu[i].t;
  EXPECT_FALSE(x.add(imu[i]).has_value()) << "past the horizon: the LiDAR stopped";
  x.anchor(m.state(imu[i].t));
  EXPECT_FALSE(x.add(imu[i]).has_value()) << "a repeated reading";
  EXPECT_FALSE(x.add(imu[i - 3]).has_value()) << "an older reading";
  ++i;
  EXPECT_TRUE(x.add(imu[i]).has_value());
  // 80 ms without readings (over max_sample_gap_s): nothing until the next anchor.
  i += 16;
  EXPECT_FALSE(x.add(imu[i]).has_value());
  EXPECT_FALSE(x.add(imu[i + 1]).has_value());
  x.anchor(m.state(imu[i + 1].t - 0.001));
  const std::optional<InertialState> back = x.add(imu[i + 2]);
  ASSERT_TRUE(back.has_value());
  EXPECT_LT(position_error_m(*back, m), 1e-4);
}

TEST(ImuExtrapolator, AllocatesNothingAfterConstruction) {
  ADIT_REQUIRE_ALLOCATION_COUNTING();
  const Motion m;
  ImuExtrapolatorConfig config;
  config.capacity = 64;  // overwritten several times over
  ImuExtrapolator x(config);
  const std::vector<ImuSample> imu = samples(m, 1.0, 3.0, kRate);
  const std::uint64_t before = adit::test::allocations();
  std::size_t given = 0;
  for (std::size_t i = 0; i < imu.size(); ++i) {
    if (i % 20 == 10) x.anchor(m.state(imu[i - 5].t));
    given += x.add(imu[i]).has_value();
  }
  EXPECT_EQ(adit::test::allocations(), before);
  EXPECT_GT(given, 350U);
}

}  // namespace
}  // namespace adit::slam
