#include "adit/sim/ouster_imu_packet.hpp"

#include <bit>
#include <cmath>
#include <numbers>

namespace adit::sim {
namespace {

void put_u64(std::uint8_t* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

void put_f32(std::uint8_t* p, double value, double step) {
  const auto bits = std::bit_cast<std::uint32_t>(static_cast<float>(std::round(value / step) * step));
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(bits >> (8 * i));
}

}  // namespace

std::array<std::uint8_t, drivers::kOusterImuPacketBytes> encode_ouster_imu_packet(const ImuSample& s,
                                                                                    std::uint64_t time_ns) {
  std::array<std::uint8_t, drivers::kOusterImuPacketBytes> packet{};
  put_u64(packet.data(), time_ns);
  put_u64(packet.data() + 8, time_ns);
  put_u64(packet.data() + 16, time_ns);
  for (int axis = 0; axis < 3; ++axis) {
    put_f32(packet.data() + 24 + 4 * axis, s.accel(axis) / kStandardGravity, kOusterImuAccelStepG);
    put_f32(packet.data() + 36 + 4 * axis, s.gyro(axis) * 180.0 / std::numbers::pi, kOusterImuGyroStepDps);
  }
  return packet;
}

}  // namespace adit::sim
