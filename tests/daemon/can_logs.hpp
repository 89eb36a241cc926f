#pragma once
// CAN logs and configs for the daemon's tests: a robot driving straight at
// 1 m/s (wheels on 0x300 as two little-endian uint16 rim speeds in mm/s,
// 100 Hz from t = 1000 s) and, optionally, an accelerometer on 0x310 (x, y, z
// as int16 in mm/s², reading (0.1, -0.2, 9.8) m/s², 0.3 ms after each wheel frame).

#include <array>
#include <cstdint>
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

// An IMU alone on the bus, as the simulator writes it for a drone (no
// wheels): accelerometer frames on 0x190 (x, y, z as int16 LE, 0.001 m/s²)
// and, 100 µs after each, gyroscope frames on 0x191 (int16 LE, 0.0002 rad/s),
// 100 Hz from t0 (1000 s). The readings wander by a few steps so that no axis
// is stuck; `line` may rewrite or drop (empty) a reading's frames: it gets
// the reading's index and its two frames.
struct ImuFrames {
  double t = 0.0;
  std::array<int, 3> accel{};
  std::array<int, 3> gyro{};
  bool with_gyro = true;
  bool skip = false;
};

inline std::string int16_le(const std::array<int, 3>& v) {
  std::string hex;
  for (const int x : v) {
    const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(x));
    hex += fmt::format("{:02X}{:02X}", u & 0xFF, u >> 8);
  }
  return hex;
}

template <typename Edit>
std::filesystem::path imu_only_log(double seconds, const std::string& name, Edit&& edit, double t0 = 1000.0) {
  const std::filesystem::path file = binary_dir() / fmt::format("{}-{}.log", name, ::getpid());
  std::ofstream out(file);
  for (int i = 0; i <= static_cast<int>(seconds * 100); ++i) {
    ImuFrames f;
    f.t = t0 + 0.01 * i;
    f.accel = {100 + i % 7, -200 - i % 3, 9800 + i % 5};  // (0.1, -0.2, 9.8) m/s²
    f.gyro = {50 + i % 3, -100 - i % 4, 2500 + i % 5};    // (0.01, -0.02, 0.5) rad/s
    edit(i, f);
    if (f.skip) continue;
    out << fmt::format("({:.6f}) can0 190#{}\n", f.t, int16_le(f.accel));
    if (f.with_gyro) out << fmt::format("({:.6f}) can0 191#{}\n", f.t + 0.0001, int16_le(f.gyro));
  }
  return file;
}

// The IMU of imu_only_log, without wheels (imu.enabled, gyroscope signals).
inline config::Config imu_only_config(const std::filesystem::path& log) {
  config::Config c;
  c.can.enabled = true;
  c.can.source = config::CanSource::candump;
  c.can.log = log.string();
  for (int axis = 0; axis < 6; ++axis) {
    config::CanSignal s;
    s.name = fmt::format("imu_{}_{}", axis < 3 ? "accel" : "gyro", "xyz"[axis % 3]);
    s.id = axis < 3 ? 0x190 : 0x191;
    s.start_bit = 16 * (axis % 3);
    s.length = 16;
    s.value_type = config::ValueType::signed_int;
    s.factor = axis < 3 ? 0.001 : 0.0002;
    s.unit = axis < 3 ? "m/s2" : "rad/s";
    c.can.signals.push_back(s);
  }
  c.wheel_odometry.enabled = false;
  c.imu.enabled = true;
  c.imu.accel_x_signal = "imu_accel_x";
  c.imu.accel_y_signal = "imu_accel_y";
  c.imu.accel_z_signal = "imu_accel_z";
  c.imu.gyro_x_signal = "imu_gyro_x";
  c.imu.gyro_y_signal = "imu_gyro_y";
  c.imu.gyro_z_signal = "imu_gyro_z";
  return c;
}

}  // namespace adit::test
