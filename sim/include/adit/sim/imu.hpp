#pragma once
// The robot's accelerometer, as CAN frames for the candump log: specific
// force f = Rᵀ·(a + g·ẑ) in the body axes (a the body's acceleration in the
// world, R its orientation, g = 9.80665 m/s² down), with white noise and a
// constant bias per axis, as three int16 little-endian values in one frame.
// The defaults are a tactical-grade MEMS accelerometer: 60 µg/√Hz noise
// density read at 100 Hz (about 50 Hz of bandwidth: σ 4.2 mm/s² per sample)
// and a bias of σ 1 mg per axis left after calibration (0.06° of tilt each).
// No gyroscope: the odometry uses gravity only.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "adit/drivers/can/frame.hpp"
#include "adit/sim/body_track.hpp"

namespace adit::sim {

struct ImuOptions {
  double rate_hz = 100.0;
  double noise_mps2 = 0.0042;       // σ per sample and axis
  double bias_sigma_mps2 = 0.0098;  // σ of each axis's constant bias (1 mg)
  double lsb_mps2 = 0.001;          // int16 resolution: ±32.7 m/s²
  double time_offset_s = 0.0;       // CAN clock minus the LiDAR clock
  std::int64_t start_time_ns = 0;
  std::uint64_t seed = 0;
  std::uint32_t id = 0x190;
};

struct ImuTruth {
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();  // m/s², body axes
};

// Specific force in the body frame at trajectory sample i: the robot's
// acceleration as a wheeled vehicle moves (along and across its heading,
// plus the bumps' vertical), gravity added, in the body axes.
Eigen::Vector3d specific_force_at(const BodyTrack& body, std::size_t i);

// Appends the accelerometer's frames to `frames` (time order).
ImuTruth simulate_imu(const BodyTrack& body, const ImuOptions& options, std::vector<drivers::can::Frame>& frames);

}  // namespace adit::sim
