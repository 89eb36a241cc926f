#pragma once
// Livox point and IMU packets written from measurements, the inverse of
// LivoxDecoder (layouts: livox_packet.hpp). The simulator and the tests use it.
// SDK2 point packets are cartesian-high (data type 1), SDK1 ones extend
// cartesian (type 2, 96 points) or dual extend cartesian (type 4, 48 x 2).

#include <cstddef>
#include <cstdint>
#include <span>

#include "adit/drivers/lidar/livox_packet.hpp"

namespace adit::drivers {

struct LivoxRawPoint {
  std::int32_t x_mm = 0, y_mm = 0, z_mm = 0;  // (0, 0, 0): no return
  std::uint8_t reflectivity = 0;
  std::uint8_t tag = 0;
};

struct LivoxSdk2PointPacket {
  std::int64_t time_ns = 0;           // the first point's time
  std::uint16_t time_interval = 0;    // 0.1 µs: the span of the packet's points
  std::uint16_t udp_cnt = 0;
  std::uint8_t frame_cnt = 0;
  std::uint8_t time_type = 1;         // 1: gPTP-synchronised
  std::span<const LivoxRawPoint> points;
};

inline constexpr std::size_t kLivoxMid360PointsPerPacket = 96;
inline constexpr std::size_t kLivoxSdk2ImuPacketBytes = kLivoxSdk2HeaderBytes + kLivoxImuBytes;  // 60
inline constexpr std::size_t kLivoxSdk1ImuPacketBytes = kLivoxSdk1HeaderBytes + kLivoxImuBytes;  // 42

constexpr std::size_t livox_sdk2_point_packet_bytes(std::size_t points) { return kLivoxSdk2HeaderBytes + 14 * points; }

// CRC-32 (IEEE 802.3, reflected, the one SDK2 puts over the data).
std::uint32_t livox_crc32(std::span<const std::uint8_t> data);

// `out` must be livox_sdk2_point_packet_bytes(points.size()) long.
void encode_livox_sdk2_points(const LivoxSdk2PointPacket& packet, std::span<std::uint8_t> out);
// `out` must be kLivoxSdk2ImuPacketBytes long. Accelerations in g, as the sensor sends them.
void encode_livox_sdk2_imu(std::int64_t time_ns, std::uint16_t udp_cnt, const float (&gyro_rad_s)[3],
                           const float (&accel_g)[3], std::span<std::uint8_t> out);

// SDK1: `points` holds 96 single (data type 2) or 96 = 48 x 2 dual (type 4, returns of one firing
// adjacent); `out` must be 18 + 96 x 14 = 1362 bytes.
inline constexpr std::size_t kLivoxSdk1PointPacketBytes = kLivoxSdk1HeaderBytes + 96 * 14;
void encode_livox_sdk1_points(std::int64_t time_ns, bool dual, std::span<const LivoxRawPoint, 96> points,
                              std::span<std::uint8_t> out);
void encode_livox_sdk1_imu(std::int64_t time_ns, const float (&gyro_rad_s)[3], const float (&accel_g)[3],
                           std::span<std::uint8_t> out);

}  // namespace adit::drivers
