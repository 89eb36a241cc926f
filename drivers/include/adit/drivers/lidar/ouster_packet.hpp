#pragma once
// The byte layout of Ouster lidar and IMU packets, per UDP profile (Ouster
// firmware user manual 2.x/3.x, "Sensor Data": "Lidar Data Packet Format",
// "Lidar Data Profiles" and "IMU Data Format"). All fields are little-endian.
//
//   LEGACY:    no packet header; per column a 16-byte header (timestamp u64 ns,
//              measurement id u16, frame id u16, encoder count u32), H pixels
//              of 12 bytes, a 4-byte status (0xFFFFFFFF: valid); no footer.
//   others:    32-byte packet header (packet type u16 = 1, frame id u16, ...),
//              per column a 12-byte header (timestamp u64 ns, measurement id
//              u16, status u16, bit 0 = valid), H pixels, 32-byte footer.
//   pixels:    RNG19_RFL8_SIG16_NIR16 12 bytes, RNG15_RFL8_NIR8 4 bytes
//              (range x8 mm, near-IR x16), RNG19_RFL8_SIG16_NIR16_DUAL 16 bytes.
//
// Readers take a pointer to a packet that was size-checked against the
// layout; they do no bounds checks themselves (hot path).

#include <cstddef>
#include <cstdint>
#include <span>

#include "adit/drivers/lidar/ouster_metadata.hpp"

namespace adit::drivers {

struct OusterPacketLayout {
  OusterProfile profile = OusterProfile::legacy;
  int columns_per_packet = 0;
  int pixels_per_column = 0;
  std::size_t packet_header_bytes = 0;
  std::size_t column_header_bytes = 0;
  std::size_t pixel_bytes = 0;
  std::size_t column_status_bytes = 0;  // the legacy trailing status word
  std::size_t packet_footer_bytes = 0;
  std::size_t column_bytes = 0;
  std::size_t packet_bytes = 0;
  int returns = 1;  // 2 for the dual profile

  static OusterPacketLayout of(const OusterMetadata& metadata);
  static OusterPacketLayout of(OusterProfile profile, int columns_per_packet, int pixels_per_column);

  const std::uint8_t* column(const std::uint8_t* packet, int c) const {
    return packet + packet_header_bytes + static_cast<std::size_t>(c) * column_bytes;
  }
  const std::uint8_t* pixel(const std::uint8_t* column, int row) const {
    return column + column_header_bytes + static_cast<std::size_t>(row) * pixel_bytes;
  }
};

inline constexpr std::size_t kOusterImuPacketBytes = 48;

namespace ouster_le {
inline std::uint16_t u16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | p[1] << 8); }
inline std::uint32_t u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}
inline std::uint64_t u64(const std::uint8_t* p) { return u32(p) | static_cast<std::uint64_t>(u32(p + 4)) << 32; }
}  // namespace ouster_le

// One column's header, in the SDK's terms (ColHeader). Fields a profile does
// not carry read as 0: the encoder count and per-column frame id exist only
// in LEGACY packets.
struct OusterColumnHeader {
  std::uint64_t timestamp_ns = 0;
  std::uint16_t measurement_id = 0;
  std::uint16_t frame_id = 0;
  std::uint32_t encoder_count = 0;
  std::uint32_t status = 0;
  bool valid = false;
};

OusterColumnHeader read_column_header(const OusterPacketLayout& layout, const std::uint8_t* column);

// The frame id of a packet: the packet header's for the new profiles, the
// first column's for LEGACY.
std::uint16_t read_packet_frame_id(const OusterPacketLayout& layout, const std::uint8_t* packet);

// One return of one pixel, with the profile's multipliers applied (range in
// mm, near-IR in the sensor's 16-bit scale), as the SDK's field extraction.
struct OusterReturn {
  std::uint32_t range_mm = 0;
  std::uint16_t signal = 0;
  std::uint16_t near_ir = 0;
  std::uint8_t reflectivity = 0;
  std::uint8_t flags = 0;
};

inline OusterReturn read_return(OusterProfile profile, const std::uint8_t* px, int return_index) {
  using namespace ouster_le;
  OusterReturn r;
  switch (profile) {
    case OusterProfile::legacy:
      r.range_mm = u32(px) & 0x000FFFFFU;  // 20 bits
      r.flags = static_cast<std::uint8_t>(px[3] >> 4);
      r.reflectivity = px[4];
      r.signal = u16(px + 6);
      r.near_ir = u16(px + 8);
      break;
    case OusterProfile::rng19_rfl8_sig16_nir16:
      r.range_mm = u32(px) & 0x0007FFFFU;  // 19 bits
      r.flags = static_cast<std::uint8_t>(px[2] >> 3);
      r.reflectivity = px[4];
      r.signal = u16(px + 6);
      r.near_ir = u16(px + 8);
      break;
    case OusterProfile::rng15_rfl8_nir8:
      r.range_mm = (u16(px) & 0x7FFFU) * 8U;  // 15 bits in units of 8 mm
      r.flags = static_cast<std::uint8_t>(px[1] >> 7);
      r.reflectivity = px[2];
      r.near_ir = static_cast<std::uint16_t>(px[3] * 16U);  // 8 bits in units of 16
      break;
    case OusterProfile::rng19_rfl8_sig16_nir16_dual: {
      const std::uint8_t* rp = px + 4 * return_index;  // range+flags+refl word of this return
      r.range_mm = u32(rp) & 0x0007FFFFU;
      r.flags = static_cast<std::uint8_t>(rp[2] >> 3);
      r.reflectivity = rp[3];
      r.signal = u16(px + 8 + 2 * return_index);
      r.near_ir = u16(px + 12);
      break;
    }
  }
  return r;
}

// An IMU packet (48 bytes, IMU profile LEGACY), in SI units in the IMU frame
// (imu_to_sensor_transform maps it to the sensor frame).
struct OusterImuSample {
  std::uint64_t system_time_ns = 0;  // when the packet was formed
  std::uint64_t accel_time_ns = 0;
  std::uint64_t gyro_time_ns = 0;
  float accel_mps2[3] = {0, 0, 0};   // from g: x 9.80665 m/s² per g
  float gyro_radps[3] = {0, 0, 0};   // from deg/s
};

// nullopt-free: returns false for anything that is not a 48-byte IMU packet.
bool decode_ouster_imu(std::span<const std::uint8_t> payload, OusterImuSample& out);

}  // namespace adit::drivers
