#pragma once
// Hesai PandarXT32 data packets written from measurements (single return), the
// inverse of HesaiDecoder for protocol 6.1: 12-byte pre-header and header
// (0xEEFF, protocol 6.1, 32 lasers, 8 blocks, distance unit 4 mm), 8 blocks of
// (azimuth u16 in 0.01°, 32 × (distance u16, reflectivity, reserved))
// little-endian, and the tail (return mode, motor speed, UTC date-time,
// µs timestamp, UDP sequence). The simulator uses it.

#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "adit/drivers/lidar/hesai.hpp"

namespace adit::drivers {

inline constexpr std::size_t kHesaiXt32PacketSize = 1080;
inline constexpr float kHesaiXt32DistanceUnit = 0.004F;

struct HesaiXt32Packet {
  std::array<std::uint16_t, 8> azimuth{};  // 0.01°
  std::array<std::uint16_t, 8 * 32> distance{};  // 4 mm units, 0 = no return
  std::array<std::uint8_t, 8 * 32> reflectivity{};
  std::int64_t time_ns = 0;  // the packet's timestamp (µs resolution on the wire)
  std::uint16_t rpm = 600;
  std::uint32_t sequence = 0;
};

void encode_hesai_xt32_packet(const HesaiXt32Packet& packet, std::span<std::uint8_t, kHesaiXt32PacketSize> out);

// Nominal XT32 angles (PandarXT32 user manual: elevations +15° to −16° in 1°
// steps, channel 1 highest; no azimuth offsets), and the CSV parse_hesai_angle_csv reads.
HesaiAngleCorrection hesai_xt32_nominal_angles();
std::string format_hesai_angle_csv(const HesaiAngleCorrection& angles);

}  // namespace adit::drivers
