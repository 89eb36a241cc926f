#pragma once
// CAN logs and configs for the daemon's tests: a robot driving straight at
// 1 m/s (wheels on 0x300 as two little-endian uint16 rim speeds in mm/s,
// 100 Hz from t = 1000 s) and, optionally, an accelerometer on 0x310 (x, y, z
// as int16 in mm/s², reading (0.1, -0.2, 9.8) m/s², 0.3 ms after each wheel frame).

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <fmt/format.h>

#include "adit/config/config.hpp"
#include "shared_data.hpp"

namespace adit::test {

inline std::filesystem::path straight_drive_log(double seconds, const std::string& name, bool accelerometer = false) {
  const std::filesystem::path file = binary_dir() / fmt::format("{}-{}.log", name, ::getpid());
  std::ofstream out(file);
  for (int i = 0; i <= static_cast<int>(seconds * 100); ++i) {
    out << fmt::format("({:.6f}) can0 300#E803E803\n", 1000.0 + 0.01 * i);
    if (accelerometer) out << fmt::format("({:.6f}) can0 310#640038FF4826\n", 1000.0 + 0.01 * i + 0.0003);
  }
  return file;
}

inline config::Config wheel_config(const std::filesystem::path& log) {
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

// The accelerometer's three signals on 0x310, mounted as the body (imu.rpy_deg 0).
inline void add_accelerometer(config::Config& c) {
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
}

}  // namespace adit::test
