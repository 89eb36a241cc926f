#pragma once
// A six-axis IMU (gyroscope and accelerometer) on any platform: what it would
// read, sample by sample, riding on a BodyTrack. The true motion at the IMU
// (imu_kinematics.hpp) plus a datasheet-style error model:
//   white noise    σ per sample = noise density · √rate (IEEE Std 952-1997's
//                  angle / velocity random walk, as Kalibr's IMU noise model);
//   bias           a turn-on value per axis, then a random walk: each sample
//                  adds N(0, (walk · √(1/rate))²), a cumulative sum of the
//                  counter-based draws (hash_noise.hpp) taken in sample
//                  order, so it is the same whatever the thread count;
//   vibration      the drone's rotors (rotor_vibration.hpp), sampled at the
//                  IMU's instants so that it aliases as on a real IMU.
// Defaults: the ADIS16448 as the EuRoC MAV dataset describes it (Burri et
// al., IJRR 2016, and its Kalibr sensor.yaml), the same numbers as the
// config's imu: section. Note that EuRoC's bias walks are an estimator's
// tuning, generous against the datasheet's in-run stability (accelerometer
// 0.25 mg, reached by this walk in about a second): they make a hard case.
// Samples are values; sim/imu_frames.hpp puts them into CAN frames and
// ouster_imu_packet.hpp into Ouster IMU packets.

#include <cstdint>
#include <numbers>
#include <vector>

#include <Eigen/Geometry>

#include "adit/sim/body_track.hpp"
#include "adit/sim/rotor_vibration.hpp"

namespace adit::sim {

inline constexpr double kStandardGravity = 9.80665;  // m/s² (CGPM 1901)

struct ImuNoise {
  double gyro_noise_density = 1.7e-4;   // rad/s/√Hz
  double accel_noise_density = 2.0e-3;  // m/s²/√Hz
  double gyro_bias_walk = 1.9e-5;       // rad/s²/√Hz
  double accel_bias_walk = 3.0e-3;      // m/s³/√Hz
  // Turn-on bias σ per axis. Gyroscope 0.2°/s: a MEMS gyro's bias left after
  // factory calibration is some tenths of a degree per second (consumer
  // parts several °/s), enough that an estimator must estimate it (12° of
  // yaw a minute if ignored) and small enough for a one-second static start
  // to measure it to a few percent. Accelerometer 1 mg: what the robot's
  // accelerometer had (a part calibrated in the payload), 0.06° of tilt per
  // axis; the map's up comes from it (decision 008).
  double gyro_turn_on_sigma = 0.2 * std::numbers::pi / 180.0;  // rad/s
  double accel_turn_on_sigma = 0.0098;                         // m/s²

  static ImuNoise none() { return {0.0, 0.0, 0.0, 0.0, 0.0, 0.0}; }
};

// How the body's linear acceleration is derived from its track.
enum class ImuMotion {
  wheeled,  // the robot's: along and across its heading from its wheel inputs (see wheeled_acceleration)
  smooth,   // second difference of the track over ±kSmoothSpan (drone, handheld)
};

struct ImuOptions {
  double rate_hz = 200.0;
  ImuNoise noise;
  RotorVibration vibration;  // off unless enabled
  // The IMU in the body frame: its origin (the lever arm) and its axes.
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  double time_offset_s = 0.0;  // the IMU's clock minus the LiDAR's (the samples' stamps)
  ImuMotion motion = ImuMotion::wheeled;
  std::uint64_t seed = 0;
};

struct ImuSample {
  double t = 0.0;      // when it was measured, s since the start on the LiDAR's clock
  double stamp = 0.0;  // t + time_offset_s: what the IMU's clock says
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();         // rad/s, IMU axes
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();        // m/s², IMU axes (specific force)
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();    // the truth inside `gyro`
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();   // the truth inside `accel`
};

// The robot's acceleration in the world at trajectory sample i, as a wheeled
// vehicle moves (along and across its heading, plus the bumps' vertical).
Eigen::Vector3d wheeled_acceleration(const BodyTrack& body, std::size_t i);
// Specific force in the body frame at trajectory sample i for the robot (at the body origin).
Eigen::Vector3d specific_force_at(const BodyTrack& body, std::size_t i);

// Samples at t = k / rate for k = 0 … duration · rate.
std::vector<ImuSample> simulate_imu(const BodyTrack& body, const ImuOptions& options);

}  // namespace adit::sim
