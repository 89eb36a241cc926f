#pragma once
// Ouster lidar packets written field by field, the inverse of OusterDecoder,
// byte by byte from the firmware manual's layout ("Lidar Data Packet Format",
// ouster_packet.hpp) and independently of the decoder's readers. The
// simulator writes its OS1-64 packets with it and the decoder tests build
// their packets with it. Also the nominal OS1-64 metadata (LEGACY profile,
// 1024x10) and a writer of the flat metadata JSON of firmware 2.x.

#include <cstdint>
#include <span>
#include <string>

#include "adit/drivers/lidar/ouster_metadata.hpp"
#include "adit/drivers/lidar/ouster_packet.hpp"

namespace adit::drivers {

// Encoder counts per revolution of every OS sensor (firmware manual: the
// encoder count of a column is its azimuth in 1/90112 of a turn).
inline constexpr std::uint32_t kOusterEncoderTicksPerRevolution = 90112;

class OusterPacketEncoder {
 public:
  // Clears `packet` (exactly layout.packet_bytes long) and marks it a lidar
  // packet (packet type 1 in the new profiles' header).
  OusterPacketEncoder(const OusterPacketLayout& layout, std::span<std::uint8_t> packet);

  // The frame id: in the packet header (new profiles) or in every column (LEGACY).
  OusterPacketEncoder& frame_id(std::uint16_t id);
  // Timestamp, measurement id and status (valid or not) of column c.
  OusterPacketEncoder& column_header(int c, std::uint64_t timestamp_ns, std::uint16_t measurement_id,
                                     bool valid = true);
  // LEGACY only (the new profiles carry no encoder count).
  OusterPacketEncoder& encoder_count(int c, std::uint32_t count);
  // Raw little-endian bytes (n ≤ 8) of pixel (c, row) at `offset` within the pixel.
  OusterPacketEncoder& pixel_bytes(int c, int row, std::size_t offset, std::uint64_t value, int n);
  // A return in the profile's encoding (range in mm, representable in the profile's field).
  OusterPacketEncoder& pixel(int c, int row, std::uint32_t range_mm, std::uint8_t reflectivity, std::uint16_t signal,
                             std::uint16_t near_ir);

  std::span<const std::uint8_t> bytes() const { return packet_; }

 private:
  std::size_t column(int c) const;
  void put(std::size_t at, std::uint64_t value, int n);

  OusterPacketLayout layout_;
  std::span<std::uint8_t> packet_;
};

// A nominal OS1-64 (gen 1, firmware 2.x) in mode 1024x10, LEGACY profile,
// ports 7502/7503: 64 beams evenly spread over +16.6°…−16.6°, beam azimuths
// in the four-column stagger of the OS1-64 (+3.1°, +0.9°, −1.3°, −3.4°, the
// rounded values of a unit's calibration) with that unit's destaggering
// shifts (19, 13, 7, 1 columns), beam origin 12.163 mm, the
// standard lidar-to-sensor transform (180° about z, 36.18 mm up).
OusterMetadata ouster_os1_64_nominal_metadata();

// The flat ("legacy") metadata JSON that firmware 2.x serves
// (get_sensor_info + get_beam_intrinsics + data_format), which
// parse_ouster_metadata reads back to the same values.
std::string format_ouster_metadata(const OusterMetadata& metadata);

}  // namespace adit::drivers
