#pragma once
// Livox UDP point and IMU packets, both protocols, as plain layout facts and a
// header parser shared by the decoder, the encoder, detection and the fuzzer.
//
// SDK2 (Mid-360; Livox-SDK2 include/livox_lidar_def.h "LivoxLidarEthernetPacket",
// livox_ros_driver2 src/comm/pub_handler.cpp), little-endian, 36-byte header:
//   0 version (0), 1 length u16 (the whole packet), 3 time_interval u16 (0.1 µs:
//   the span of the packet's points), 5 dot_num u16, 7 udp_cnt u16, 9 frame_cnt,
//   10 data_type, 11 time_type, 12 reserved[12], 24 crc32 u32 (of the data),
//   28 timestamp u64 (ns), 36 data.
//   data_type 0 IMU (6 x f32: gyro x y z rad/s, acc x y z g), 1 cartesian high
//   (x y z i32 mm, reflectivity, tag: 14 bytes), 2 cartesian low (x y z i16 cm,
//   reflectivity, tag: 8), 3 spherical (depth u32 mm, zenith u16 and azimuth u16
//   in 0.01°, reflectivity, tag: 10). Point i fires at timestamp +
//   i x (time_interval x 100 / dot_num) ns (pub_handler.cpp). The Mid-360 sends
//   points from UDP 56300 to the host's 56301 and IMU from 56400 to 56401
//   (livox_ros_driver2 config/MID360_config.json).
// SDK1 (Avia, Horizon, Tele, Mid-70; Livox-SDK sdk_core/include/livox_def.h
// "LivoxEthPacket", livox_ros_driver lds.h), little-endian, 18-byte header:
//   0 version (5), 1 slot, 2 id, 3 reserved, 4 err_code u32, 8 timestamp_type,
//   9 data_type, 10 timestamp[8], 18 data. data_type 0 cartesian (x y z i32 mm,
//   reflectivity: 13 bytes x 100), 1 spherical (depth u32, theta u16, phi u16,
//   reflectivity: 9 x 100), 2 extend cartesian (+tag: 14 x 96), 3 extend
//   spherical (10 x 96), 4 dual extend cartesian (2 x (x y z, refl, tag): 28 x 48),
//   5 dual extend spherical (theta, phi, 2 x (depth, refl, tag): 16 x 48),
//   6 IMU (24 x 1), 7 triple extend cartesian (42 x 30), 8 triple extend
//   spherical (22 x 30). Timestamp types 0 (no sync), 1 (PTP), 4 (PPS): u64 ns;
//   3 (GPS): UTC year-2000, month, day, hour, u32 µs within the hour. The Avia
//   fires a point (all its returns) every 4.167 µs (240 k/s; livox_ros_driver
//   lds.h product table), 6 lines.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

namespace adit::drivers {

enum class LivoxProtocol : std::uint8_t { sdk1, sdk2 };

inline constexpr std::size_t kLivoxSdk2HeaderBytes = 36;
inline constexpr std::size_t kLivoxSdk1HeaderBytes = 18;
inline constexpr std::uint8_t kLivoxSdk1Version = 5;
inline constexpr std::uint8_t kLivoxSdk2Version = 0;
inline constexpr std::uint16_t kLivoxMid360PointPort = 56301;  // host side
inline constexpr std::uint16_t kLivoxMid360ImuPort = 56401;
inline constexpr std::uint16_t kLivoxAviaDataPort = 56001;     // livox_ros_driver's default host data port
inline constexpr std::size_t kLivoxImuBytes = 24;
inline constexpr double kLivoxStandardGravity = 9.80665;      // the IMU's accelerations are in g

// SDK2 data types.
inline constexpr std::uint8_t kLivoxSdk2Imu = 0, kLivoxSdk2CartesianHigh = 1, kLivoxSdk2CartesianLow = 2,
                              kLivoxSdk2Spherical = 3;
// SDK1 data types.
inline constexpr std::uint8_t kLivoxSdk1Cartesian = 0, kLivoxSdk1Spherical = 1, kLivoxSdk1ExtendCartesian = 2,
                              kLivoxSdk1ExtendSpherical = 3, kLivoxSdk1DualCartesian = 4,
                              kLivoxSdk1DualSpherical = 5, kLivoxSdk1Imu = 6, kLivoxSdk1TripleCartesian = 7,
                              kLivoxSdk1TripleSpherical = 8;

// How one data type lays out its points.
struct LivoxDataFormat {
  std::size_t record_bytes = 0;  // one record (a firing: all its returns)
  std::size_t records = 0;       // per packet (SDK1: fixed; SDK2: dot_num says)
  std::size_t returns = 1;       // returns per record
  bool spherical = false;
  bool imu = false;
};
// nullopt for a data type the protocol does not define.
std::optional<LivoxDataFormat> livox_data_format(LivoxProtocol protocol, std::uint8_t data_type);

// The header of one packet, checked against its size.
struct LivoxHeader {
  LivoxProtocol protocol = LivoxProtocol::sdk2;
  std::uint8_t data_type = 0;
  LivoxDataFormat format;
  std::size_t records = 0;           // records in this packet
  std::int64_t timestamp_ns = 0;     // the first record's time on the sensor clock
  std::uint8_t time_type = 0;
  std::uint32_t record_interval_ns = 0;  // SDK2: from time_interval; SDK1: 0 (the model's rate applies)
  std::optional<std::uint16_t> sequence;  // SDK2 udp_cnt
};

enum class LivoxHeaderStatus : std::uint8_t { ok, foreign, truncated, malformed };

struct LivoxHeaderResult {
  LivoxHeaderStatus status = LivoxHeaderStatus::foreign;
  LivoxHeader header;
};

// Reads the header of `packet` in `protocol`: foreign when the version byte
// differs, truncated when shorter than the header or than its data needs,
// malformed for an unknown data type, a length field that disagrees with the
// size, an impossible count or time.
LivoxHeaderResult parse_livox_header(LivoxProtocol protocol, std::span<const std::uint8_t> packet);

// One IMU reading, in the sensor's axes, on the sensor clock.
struct LivoxImuReading {
  std::int64_t sensor_time_ns = 0;
  float gyro_rad_s[3] = {0, 0, 0};
  float accel_m_s2[3] = {0, 0, 0};  // converted from g
};

// The reading an IMU packet carries (either protocol); nullopt otherwise.
std::optional<LivoxImuReading> decode_livox_imu(std::span<const std::uint8_t> packet);

}  // namespace adit::drivers
