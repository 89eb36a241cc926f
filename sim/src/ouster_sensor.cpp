// The OS1-64 as a SpinningSensor: mode 1024x10, LEGACY profile (firmware 2.x).
// A block is a column: the 64 pixels of a column are measured together at the
// column's timestamp, at the encoder angle of its measurement id
// (360°·mid/1024), each beam turned by its beam azimuth angle; columns follow
// each other every 1/10240 s, 16 per packet (640 packets/s). The geometry is
// the firmware manual's XYZ equations, which the decoder inverts: the beam
// leaves its origin, lidar_origin_to_beam_origin_mm out along the encoder
// direction, the range counts from the lidar origin (so includes that offset),
// and lidar_to_sensor_transform takes the lidar frame to the sensor frame. The
// metadata JSON is written next to the pcap. Timestamps are Unix time, as from
// a PTP-synchronised sensor. Signal and near-IR are not simulated (0).
#include <array>
#include <cmath>
#include <numbers>

#include "adit/drivers/lidar/ouster_encoder.hpp"
#include "adit/sim/spinning_lidar.hpp"

namespace adit::sim {

SpinningSensor ouster_os1_64_sensor() {
  using namespace adit::drivers;
  const OusterMetadata m = ouster_os1_64_nominal_metadata();
  const OusterPacketLayout layout = OusterPacketLayout::of(m);
  SpinningSensor s;
  s.model = "OS1-64";
  s.port = m.udp_port_lidar;
  s.packet_size = layout.packet_bytes;
  s.blocks = static_cast<std::size_t>(m.columns_per_packet);
  s.channels = static_cast<std::size_t>(m.pixels_per_column);
  s.block_azimuth = true;
  s.fixed_rpm = 60.0 * m.frame_rate_hz;
  const double column_ns = 1e9 / (m.frame_rate_hz * m.columns_per_frame);  // 97656.25 ns
  s.packet_period_ns = std::llround(column_ns * m.columns_per_packet);       // 1.5625 ms exactly
  for (std::size_t c = 0; c < s.blocks; ++c) {
    for (std::size_t row = 0; row < s.channels; ++row) {
      s.firing_ns[c * s.channels + row] = std::llround(static_cast<double>(c) * column_ns);
      s.beam[c * s.channels + row] = static_cast<std::uint16_t>(row);
    }
  }
  const double deg = std::numbers::pi / 180.0;
  const double beam_origin_m = m.lidar_origin_to_beam_origin_mm * 1e-3;
  for (std::size_t i = 0; i < m.beam_altitude_deg.size(); ++i) {
    // θ = encoder angle + beam azimuth: the manual's θe + θa with the signs of
    // a clockwise-counted head (see Beam).
    s.beams.push_back({m.beam_altitude_deg[i] * deg, m.beam_azimuth_deg[i] * deg, 0.0, 0.0, beam_origin_m});
  }
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) s.lidar_to_sensor.linear()(r, k) = m.lidar_to_sensor[static_cast<std::size_t>(4 * r + k)];
    s.lidar_to_sensor.translation()(r) = m.lidar_to_sensor[static_cast<std::size_t>(4 * r + 3)] * 1e-3;
  }
  constexpr std::uint32_t kRangeField = 0xFFFFF;  // LEGACY: 20 bits of mm
  s.max_range_m = kRangeField * 1e-3 - beam_origin_m;
  const auto width = static_cast<std::uint64_t>(m.columns_per_frame);
  const auto per_packet = static_cast<std::uint64_t>(m.columns_per_packet);
  const auto channels = s.channels;
  std::array<std::int64_t, kBlocks> column_offset_ns{};  // after the packet's first column
  for (std::size_t c = 0; c < s.blocks; ++c) column_offset_ns[c] = s.firing_ns[c * s.channels];
  s.encode = [layout, width, per_packet, channels, column_offset_ns, beam_origin_m](const SpinningPacket& in,
                                                                                    std::span<std::uint8_t> out) {
    OusterPacketEncoder e(layout, out);
    const std::uint64_t first_column = in.index * per_packet;  // since the start; frames start at column 0
    e.frame_id(static_cast<std::uint16_t>(first_column / width));
    for (std::size_t c = 0; c < per_packet; ++c) {
      const auto mid = static_cast<std::uint16_t>((first_column + c) % width);
      const auto col = static_cast<int>(c);
      e.column_header(col, static_cast<std::uint64_t>(in.time_ns + column_offset_ns[c]), mid)
          .encoder_count(col, static_cast<std::uint32_t>(mid * kOusterEncoderTicksPerRevolution / width));
      for (std::size_t row = 0; row < channels; ++row) {
        const double r = in.range_m[c * channels + row];
        if (r <= 0) continue;
        e.pixel(col, static_cast<int>(row), static_cast<std::uint32_t>(std::lround((r + beam_origin_m) * 1000.0)),
                in.reflectivity[c * channels + row], 0, 0);
      }
    }
  };
  s.calibration_file = "OS1-64.json";
  s.calibration_text = format_ouster_metadata(m);
  return s;
}

}  // namespace adit::sim
