#include "adit/sim/imu_frames.hpp"

#include <algorithm>
#include <cmath>

namespace adit::sim {
namespace {

drivers::can::Frame int16_frame(std::int64_t time_us, std::uint32_t id, const Eigen::Vector3d& value, double lsb) {
  drivers::can::Frame frame;
  frame.time_us = time_us;
  frame.id = id;
  frame.length = 6;
  frame.set_interface_name("can0");
  for (int axis = 0; axis < 3; ++axis) {
    const long counts = std::clamp(std::lround(value(axis) / lsb), -32768L, 32767L);
    const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(counts));
    frame.data[static_cast<std::size_t>(2 * axis)] = static_cast<std::uint8_t>(u & 0xFF);
    frame.data[static_cast<std::size_t>(2 * axis + 1)] = static_cast<std::uint8_t>(u >> 8);
  }
  return frame;
}

}  // namespace

void append_imu_frames(std::span<const ImuSample> samples, const ImuFrameOptions& o,
                       std::vector<drivers::can::Frame>& frames) {
  frames.reserve(frames.size() + samples.size() * (o.gyro ? 2 : 1));
  for (const ImuSample& s : samples) {
    const std::int64_t time_us = (o.start_time_ns + std::llround(s.stamp * 1e9)) / 1000 + o.latency_us;
    frames.push_back(int16_frame(time_us, o.accel_id, s.accel, o.accel_lsb));
    if (o.gyro) frames.push_back(int16_frame(time_us + o.gyro_after_us, o.gyro_id, s.gyro, o.gyro_lsb));
  }
}

}  // namespace adit::sim
