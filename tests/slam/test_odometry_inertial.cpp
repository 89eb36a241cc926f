#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "adit/slam/odometry.hpp"
#include "imu_from_motion.hpp"
#include "synthetic_scenes.hpp"

namespace adit::slam {
namespace {

constexpr double kSweep = 0.1;  // s, one turn of the sensor

// A person carrying the scanner through a hall: walking at 0.8 m/s with a
// sway, a 2 Hz step bob, and looking around with turns up to 124°/s.
Eigen::Isometry3d handheld(double t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const double yaw = 0.3 * t + 1.1 * std::sin(1.7 * t);
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(0.04 * std::sin(2.0 * M_PI * 1.0 * t + 0.4), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(0.05 * std::sin(2.0 * M_PI * 1.0 * t), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() << -2.0 + 0.8 * t, 0.5 * std::sin(0.7 * t), 0.03 * std::cos(2.0 * M_PI * 2.0 * t);
  return T;
}

// One sweep of a spinning sensor from t0: each point of `world` within range
// is seen when the turn reaches its azimuth, in the body frame of that instant.
template <typename PoseAt>
std::vector<Eigen::Vector3f> sweep(const std::vector<Eigen::Vector3f>& world, const PoseAt& pose_at, double t0,
                                   std::size_t n, unsigned seed, std::vector<float>& times) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, world.size() - 1);
  const Eigen::Isometry3d start_inverse = pose_at(t0).inverse();
  std::vector<Eigen::Vector3f> points;
  times.clear();
  while (points.size() < n) {
    const Eigen::Vector3d w = world[pick(rng)].cast<double>();
    const Eigen::Vector3d p0 = start_inverse * w;
    if (p0.norm() > 30.0 || p0.norm() < 0.5) continue;
    const double t = kSweep * (std::atan2(p0.y(), p0.x()) + M_PI) / (2.0 * M_PI);
    const Eigen::Isometry3d at = pose_at(t0 + t);
    points.push_back((at.inverse() * w).cast<float>());
    times.push_back(static_cast<float>(t));
  }
  return points;
}

// The biases of imu_readings: constant unless a test says otherwise.
const Eigen::Vector3d kGyroBias(0.004, -0.003, 0.005);
Eigen::Vector3d constant_accel_bias(double) { return {0.05, -0.04, 0.06}; }

// A MEMS IMU at 200 Hz on that body: white noise, a constant gyroscope bias
// and the accelerometer's bias at each time.
template <typename PoseAt, typename AccelBiasAt = Eigen::Vector3d (*)(double)>
std::vector<ImuSample> imu_readings(const PoseAt& pose_at, double t0, double t1, unsigned seed,
                                    const Eigen::Vector3d& gyro_bias = kGyroBias,
                                    AccelBiasAt accel_bias_at = constant_accel_bias) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gyro_noise(0.0, 0.003), accel_noise(0.0, 0.03);
  std::vector<ImuSample> out;
  for (double t = t0; t <= t1; t += 0.005) {
    ImuSample s = test::imu_sample(pose_at, t, gyro_bias, accel_bias_at(t));
    for (int i = 0; i < 3; ++i) {
      s.angular_rate(i) += gyro_noise(rng);
      s.specific_force(i) += accel_noise(rng);
    }
    out.push_back(s);
  }
  return out;
}

double angle_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() * 180.0 / M_PI;
}

struct Outcome {
  double final_position_error_m = 0.0;
  double final_rotation_error_deg = 0.0;
  double worst_rotation_error_deg = 0.0;
  int inertial_scans = 0;
  int standstill_scans = 0;
};

// Scans every `period` s along handheld(), with or without the IMU.
Outcome run(const std::vector<Eigen::Vector3f>& hall, double period, int scans, bool with_imu) {
  OdometryConfig config;
  config.max_range_m = 30.0F;
  Odometry odometry(config);
  const std::vector<ImuSample> imu = imu_readings(handheld, -0.5, period * scans + 0.5, 7);
  std::vector<float> times;
  Outcome result;
  for (int k = 0; k < scans; ++k) {
    const double t = period * k;
    const auto points = sweep(hall, handheld, t, 20000, 500 + static_cast<unsigned>(k), times);
    ScanInput input{static_cast<std::int64_t>(std::llround(t * 1e9)), points, times};
    if (with_imu) input.imu = imu;
    const OdometryResult r = odometry.process(input);
    // LiDAR only this walk is lost (decision 043): held scans are not valid.
    if (with_imu) {
      EXPECT_TRUE(r.valid) << "scan " << k << ": " << to_string(r.status);
    }
    result.inertial_scans += r.inertial ? 1 : 0;
    result.standstill_scans += r.standstill ? 1 : 0;
    const Eigen::Isometry3d expected = handheld(0.0).inverse() * handheld(t);
    result.final_position_error_m = (r.pose.translation() - expected.translation()).norm();
    result.final_rotation_error_deg = angle_deg(r.pose.linear(), expected.linear());
    result.worst_rotation_error_deg = std::max(result.worst_rotation_error_deg, result.final_rotation_error_deg);
  }
  return result;
}

// The real handheld sequence of #26 in miniature: scans 0.5 s apart while
// the carrier looks around at up to 124°/s, so up to 60° between scans.
// Registration alone must find that turn from the scans; with the IMU it
// starts within a fraction of a degree of it. The odometry starts with the
// walk under way (0.8 m/s, unknown: the start search finds it), at the top
// of a step's bob: a vertical speed unknown at the start is not searched for
// (started at 0.38 m/s up, the first registration settles 0.17 m low and
// calls z degenerate).
TEST(InertialOdometry, AHandheldScannerTurningFastIsTrackedWithScansHalfASecondApart) {
  const auto hall = test::room(400000, 41, 12.0F, 8.0F, 3.0F);
  const Outcome inertial = run(hall, 0.5, 13, true);
  EXPECT_EQ(inertial.inertial_scans, 13);
  EXPECT_EQ(inertial.standstill_scans, 0);  // walking: never taken for still
  // Measured: 0.026 m and 0.05°; LiDAR only, 5.3 m and 141° (13 m and 131° before decision 040).
  EXPECT_LT(inertial.final_position_error_m, 0.05);
  EXPECT_LT(inertial.worst_rotation_error_deg, 0.2);
  const Outcome lidar_only = run(hall, 0.5, 13, false);
  EXPECT_EQ(lidar_only.inertial_scans, 0);
  EXPECT_GT(lidar_only.worst_rotation_error_deg, 10.0);
  std::printf("position / worst rotation error: LiDAR-inertial %.3f m / %.2f°, LiDAR only %.3f m / %.2f°\n",
              inertial.final_position_error_m, inertial.worst_rotation_error_deg, lidar_only.final_position_error_m,
              lidar_only.worst_rotation_error_deg);
}

// The IMU stops for a while: those scans are LiDAR only, and the filter
// starts again from the scans once the readings come back.
TEST(InertialOdometry, AnImuDropoutFallsBackToLidarOnlyAndRecovers) {
  const auto hall = test::room(400000, 43, 12.0F, 8.0F, 3.0F);
  const auto walk = [](double t) { return handheld(0.2 * t); };  // a fifth of the pace: a 10 Hz LiDAR follows it alone
  std::vector<ImuSample> imu = imu_readings(walk, -0.5, 4.5, 9);
  std::erase_if(imu, [](const ImuSample& s) { return s.t > 1.5 && s.t < 2.0; });
  OdometryConfig config;
  config.max_range_m = 30.0F;
  Odometry odometry(config);
  std::vector<float> times;
  std::vector<bool> inertial;
  OdometryResult r;
  for (int k = 0; k < 40; ++k) {
    const double t = 0.1 * k;
    const auto points = sweep(hall, walk, t, 20000, 900 + static_cast<unsigned>(k), times);
    r = odometry.process({static_cast<std::int64_t>(std::llround(t * 1e9)), points, times, std::nullopt, imu});
    ASSERT_TRUE(r.valid) << "scan " << k;
    inertial.push_back(r.inertial);
  }
  // Scans 0-14 end before the gap, 16-19 lie in it, 22 on start after it
  // (15, 20 and 21 touch its edges).
  for (int k = 0; k < 40; ++k) {
    const bool imu = inertial[static_cast<std::size_t>(k)];
    if (k <= 14 || k >= 22) {
      EXPECT_TRUE(imu) << "scan " << k;
    } else if (k >= 16 && k <= 19) {
      EXPECT_FALSE(imu) << "scan " << k;
    }
  }
  const Eigen::Isometry3d expected = walk(0.0).inverse() * walk(3.9);
  EXPECT_LT((r.pose.translation() - expected.translation()).norm(), 0.02);
  EXPECT_LT(angle_deg(r.pose.linear(), expected.linear()), 0.2);
}

// Standing still in a corridor: the scan cannot see along it, so there the
// position is the IMU's alone. An accelerometer bias that walks after the
// start (0.05 m/s² along the corridor from t = 0.5 s, as a MEMS unit warming
// up) is read as acceleration; the zero-velocity update holds the body
// still instead, and learns the bias (standstill.hpp).
TEST(InertialOdometry, ABodyStandingInACorridorStaysPutWithTheZeroVelocityUpdate) {
  const auto corridor = test::tunnel(300000, 51, 200.0F);
  const auto rest = [](double) { return Eigen::Isometry3d::Identity(); };
  const auto warming_up = [](double t) { return Eigen::Vector3d(t > 0.5 ? 0.05 : 0.0, -0.02, 0.03); };
  const std::vector<ImuSample> imu = imu_readings(rest, -0.5, 3.5, 13, {0.004, -0.003, 0.002}, warming_up);
  const auto stand = [&](bool zero_velocity_update) {
    OdometryConfig config;
    config.max_range_m = 30.0F;
    config.standstill.enabled = zero_velocity_update;
    config.max_start_speed_mps = 0.0;  // no start search: along the corridor every offset fits alike
    Odometry odometry(config);
    std::vector<float> times;
    OdometryResult r;
    int still = 0;
    for (int k = 0; k < 30; ++k) {
      const double t = 0.1 * k;
      const auto points = sweep(corridor, rest, t, 20000, 700 + static_cast<unsigned>(k), times);
      r = odometry.process({static_cast<std::int64_t>(std::llround(t * 1e9)), points, times, std::nullopt, imu});
      EXPECT_TRUE(r.valid && r.inertial) << "scan " << k;
      still += r.standstill ? 1 : 0;
    }
    EXPECT_TRUE(r.status == OdometryStatus::degenerate) << "the corridor's axis should be unseen";
    return std::pair{r.pose.translation().norm(), still};
  };
  const auto [held, still_scans] = stand(true);
  const auto [drifted, none] = stand(false);
  std::printf("after 2.9 s standing: %.4f m off with the zero-velocity update (%d scans still), %.4f m without\n", held,
              still_scans, drifted);
  EXPECT_GE(still_scans, 25);
  EXPECT_EQ(none, 0);
  EXPECT_LT(held, 0.01);
  EXPECT_GT(drifted, 0.05);  // what the update prevents
}

}  // namespace
}  // namespace adit::slam
