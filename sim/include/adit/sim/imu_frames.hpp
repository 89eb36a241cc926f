#pragma once
// A CAN IMU's frames for the candump log: per sample, the accelerometer at
// `accel_id` (three int16 little-endian, x y z, lsb 0.001 m/s²: ±32.7 m/s²)
// and 100 µs later the gyroscope at `gyro_id` (three int16 little-endian,
// lsb 0.0002 rad/s: ±6.55 rad/s, 375°/s). Values beyond the range saturate
// at the int16 limits, as a real part's registers do. Stamped on the CAN
// clock: the sample's stamp (the IMU's clock, which is the CAN clock here).

#include <cstdint>
#include <span>
#include <vector>

#include "adit/drivers/can/frame.hpp"
#include "adit/sim/imu.hpp"

namespace adit::sim {

struct ImuFrameOptions {
  std::uint32_t accel_id = 0x190;
  std::uint32_t gyro_id = 0x191;
  double accel_lsb = 0.001;   // m/s² per count
  double gyro_lsb = 0.0002;   // rad/s per count
  std::int64_t start_time_ns = 0;
  std::int64_t latency_us = 300;  // the accelerometer frame after the sample (after the wheels' two PDOs)
  std::int64_t gyro_after_us = 100;
  bool gyro = true;           // false: an accelerometer alone
};

// Appends the frames of every sample to `frames` (each sample's accelerometer, then its gyroscope).
void append_imu_frames(std::span<const ImuSample> samples, const ImuFrameOptions& options,
                       std::vector<drivers::can::Frame>& frames);

}  // namespace adit::sim
