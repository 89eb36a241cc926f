#pragma once
// Builds synthetic Ouster lidar packets for unit tests, byte by byte from the
// firmware manual's layout (independently of the decoder's readers).

#include <cstdint>
#include <vector>

#include "adit/drivers/lidar/ouster_packet.hpp"

namespace adit::drivers::test {

class OusterPacketBuilder {
 public:
  explicit OusterPacketBuilder(const OusterPacketLayout& layout)
      : layout_(layout), bytes_(layout.packet_bytes, 0) {
    if (layout_.profile != OusterProfile::legacy) put(0, 1, 2);  // packet type: lidar
  }

  OusterPacketBuilder& frame_id(std::uint16_t id) {
    if (layout_.profile != OusterProfile::legacy) put(2, id, 2);
    for (int c = 0; c < layout_.columns_per_packet; ++c)
      if (layout_.profile == OusterProfile::legacy) put(column(c) + 10, id, 2);
    return *this;
  }

  // Timestamp, measurement id and a valid status for column c.
  OusterPacketBuilder& column_header(int c, std::uint64_t timestamp_ns, std::uint16_t measurement_id, bool valid = true) {
    put(column(c), timestamp_ns, 8);
    put(column(c) + 8, measurement_id, 2);
    if (layout_.profile == OusterProfile::legacy)
      put(column(c) + layout_.column_bytes - 4, valid ? 0xFFFFFFFFU : 0U, 4);
    else
      put(column(c) + 10, valid ? 1 : 0, 2);
    return *this;
  }

  // Writes raw bytes of pixel (c, row) at `offset` within the pixel.
  OusterPacketBuilder& pixel_bytes(int c, int row, std::size_t offset, std::uint64_t value, int n) {
    put(column(c) + layout_.column_header_bytes + static_cast<std::size_t>(row) * layout_.pixel_bytes + offset, value, n);
    return *this;
  }

  // A return with the profile's encoding (range in mm must be representable).
  OusterPacketBuilder& pixel(int c, int row, std::uint32_t range_mm, std::uint8_t reflectivity, std::uint16_t signal,
                             std::uint16_t near_ir) {
    switch (layout_.profile) {
      case OusterProfile::legacy:
      case OusterProfile::rng19_rfl8_sig16_nir16:
        pixel_bytes(c, row, 0, range_mm, 3);
        pixel_bytes(c, row, 4, reflectivity, 1);
        pixel_bytes(c, row, 6, signal, 2);
        pixel_bytes(c, row, 8, near_ir, 2);
        break;
      case OusterProfile::rng15_rfl8_nir8:
        pixel_bytes(c, row, 0, range_mm / 8, 2);
        pixel_bytes(c, row, 2, reflectivity, 1);
        pixel_bytes(c, row, 3, near_ir / 16, 1);
        break;
      case OusterProfile::rng19_rfl8_sig16_nir16_dual:
        pixel_bytes(c, row, 0, range_mm, 3);
        pixel_bytes(c, row, 3, reflectivity, 1);
        pixel_bytes(c, row, 8, signal, 2);
        pixel_bytes(c, row, 12, near_ir, 2);
        break;
    }
    return *this;
  }

  const std::vector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  std::size_t column(int c) const {
    return layout_.packet_header_bytes + static_cast<std::size_t>(c) * layout_.column_bytes;
  }
  void put(std::size_t at, std::uint64_t value, int n) {
    for (int i = 0; i < n; ++i) bytes_.at(at + static_cast<std::size_t>(i)) = static_cast<std::uint8_t>(value >> (8 * i));
  }

  OusterPacketLayout layout_;
  std::vector<std::uint8_t> bytes_;
};

}  // namespace adit::drivers::test
