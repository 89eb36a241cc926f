#include "adit/drivers/lidar/ouster_packet.hpp"

#include <bit>
#include <numbers>

namespace adit::drivers {

OusterPacketLayout OusterPacketLayout::of(const OusterMetadata& metadata) {
  return of(metadata.lidar_profile, metadata.columns_per_packet, metadata.pixels_per_column);
}

OusterPacketLayout OusterPacketLayout::of(OusterProfile profile, int columns_per_packet, int pixels_per_column) {
  OusterPacketLayout l;
  l.profile = profile;
  l.columns_per_packet = columns_per_packet;
  l.pixels_per_column = pixels_per_column;
  const bool legacy = profile == OusterProfile::legacy;
  l.packet_header_bytes = legacy ? 0 : 32;
  l.packet_footer_bytes = legacy ? 0 : 32;
  l.column_header_bytes = legacy ? 16 : 12;
  l.column_status_bytes = legacy ? 4 : 0;
  switch (profile) {
    case OusterProfile::legacy:
    case OusterProfile::rng19_rfl8_sig16_nir16: l.pixel_bytes = 12; break;
    case OusterProfile::rng15_rfl8_nir8: l.pixel_bytes = 4; break;
    case OusterProfile::rng19_rfl8_sig16_nir16_dual: l.pixel_bytes = 16; break;
  }
  l.returns = profile == OusterProfile::rng19_rfl8_sig16_nir16_dual ? 2 : 1;
  l.column_bytes = l.column_header_bytes + static_cast<std::size_t>(pixels_per_column) * l.pixel_bytes +
                   l.column_status_bytes;
  l.packet_bytes = l.packet_header_bytes + static_cast<std::size_t>(columns_per_packet) * l.column_bytes +
                   l.packet_footer_bytes;
  return l;
}

OusterColumnHeader read_column_header(const OusterPacketLayout& layout, const std::uint8_t* column) {
  using namespace ouster_le;
  OusterColumnHeader h;
  h.timestamp_ns = u64(column);
  h.measurement_id = u16(column + 8);
  if (layout.profile == OusterProfile::legacy) {
    h.frame_id = u16(column + 10);
    h.encoder_count = u32(column + 12);
    h.status = u32(column + layout.column_bytes - 4);
    h.valid = h.status == 0xFFFFFFFFU;
  } else {
    h.status = u16(column + 10);
    h.valid = (h.status & 0x1U) != 0;
  }
  return h;
}

std::uint16_t read_packet_frame_id(const OusterPacketLayout& layout, const std::uint8_t* packet) {
  return layout.profile == OusterProfile::legacy ? ouster_le::u16(packet + 10) : ouster_le::u16(packet + 2);
}

bool decode_ouster_imu(std::span<const std::uint8_t> payload, OusterImuSample& out) {
  if (payload.size() != kOusterImuPacketBytes) return false;
  const std::uint8_t* p = payload.data();
  const auto f32 = [](const std::uint8_t* q) { return std::bit_cast<float>(ouster_le::u32(q)); };
  constexpr float kStandardGravity = 9.80665F;  // m/s² per g (CGPM 1901)
  constexpr float kRadPerDeg = std::numbers::pi_v<float> / 180.0F;
  out.system_time_ns = ouster_le::u64(p);
  out.accel_time_ns = ouster_le::u64(p + 8);
  out.gyro_time_ns = ouster_le::u64(p + 16);
  for (int i = 0; i < 3; ++i) {
    out.accel_mps2[i] = f32(p + 24 + 4 * i) * kStandardGravity;
    out.gyro_radps[i] = f32(p + 36 + 4 * i) * kRadPerDeg;
  }
  return true;
}

}  // namespace adit::drivers
