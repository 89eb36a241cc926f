// The PandarXT32 as a SpinningSensor: the decoder's firing table (block m
// fires 50 µs before m + 1, channels 1.512 µs apart; the packet's timestamp
// follows the last block), every channel at its block's azimuth as Hesai's
// point formula has it, the nominal angles (written as PandarXT32.csv), the
// protocol 6.1 encoder.
#include <cmath>
#include <numbers>

#include "adit/drivers/lidar/hesai_encoder.hpp"
#include "adit/sim/spinning_lidar.hpp"
#include "block_packet.hpp"

namespace adit::sim {

SpinningSensor hesai_xt32_sensor() {
  using namespace adit::drivers;
  const HesaiModel model = HesaiModel::pandar_xt32;
  const HesaiAngleCorrection angles = hesai_xt32_nominal_angles();
  SpinningSensor s;
  s.model = "PandarXT32";
  s.port = 2368;
  s.packet_size = kHesaiXt32PacketSize;
  s.blocks = hesai_block_count(model);
  s.block_azimuth = true;
  // Firing times relative to the first firing (block 0, channel 0), which is
  // `first` after the packet's timestamp (negative: the timestamp comes later).
  const std::int32_t first = hesai_firing_ns(model, 1, 0, 0, 0);
  for (std::size_t b = 0; b < s.blocks; ++b) {
    for (std::size_t c = 0; c < kBlockChannels; ++c) {
      s.firing_ns[b * kBlockChannels + c] = hesai_firing_ns(model, 1, 0, b, c) - first;
      s.beam[b * kBlockChannels + c] = static_cast<std::uint16_t>(c);
    }
  }
  s.packet_period_ns = static_cast<std::int64_t>(s.blocks) *
                       (hesai_firing_ns(model, 1, 0, 1, 0) - hesai_firing_ns(model, 1, 0, 0, 0));
  const double deg = std::numbers::pi / 180.0;
  for (std::size_t i = 0; i < angles.elevation_deg.size(); ++i) {
    s.beams.push_back({angles.elevation_deg[i] * deg, angles.azimuth_deg[i] * deg, 0.0, 0.0, 0.0});
  }
  const double unit = kHesaiXt32DistanceUnit;
  s.max_range_m = 0xFFFF * unit;
  s.encode = [unit, first](const SpinningPacket& in, std::span<std::uint8_t> out) {
    HesaiXt32Packet p;
    p.time_ns = in.time_ns - first;
    p.sequence = static_cast<std::uint32_t>(in.index);
    for (std::size_t b = 0; b < p.azimuth.size(); ++b) {
      p.azimuth[b] = in.azimuth[b];
      for (std::size_t c = 0; c < kBlockChannels; ++c) {
        p.distance[b * kBlockChannels + c] = range_counts(in.range_m[b * kBlockChannels + c], unit);
        p.reflectivity[b * kBlockChannels + c] = in.reflectivity[b * kBlockChannels + c];
      }
    }
    encode_hesai_xt32_packet(p, out.first<kHesaiXt32PacketSize>());
  };
  s.calibration_file = "PandarXT32.csv";
  s.calibration_text = format_hesai_angle_csv(angles);
  return s;
}

}  // namespace adit::sim
