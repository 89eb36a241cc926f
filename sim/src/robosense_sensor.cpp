// The RS-16 as a SpinningSensor: the decoder's firing table (single return:
// two 16-laser sequences per block), the nominal angles (written as
// RS16.csv), the MSOP encoder.
#include <cmath>
#include <numbers>

#include "adit/drivers/lidar/robosense_encoder.hpp"
#include "adit/sim/spinning_lidar.hpp"
#include "block_packet.hpp"

namespace adit::sim {

SpinningSensor robosense_rs16_sensor() {
  using namespace adit::drivers;
  const RoboSenseModel model = RoboSenseModel::rs16;
  const RoboSenseAngles angles = robosense_nominal_angles(model);
  SpinningSensor s;
  s.model = "RS-16";
  s.port = 6699;
  s.packet_size = kRoboSenseMsopSize;
  const auto block_ns = std::llround(2.0 * robosense_sequence_us(model) * 1000.0);
  s.packet_period_ns = static_cast<std::int64_t>(s.blocks) * block_ns;
  const auto firing = robosense_firing_us(model);
  for (std::size_t b = 0; b < s.blocks; ++b) {
    for (std::size_t c = 0; c < kBlockChannels; ++c) {
      s.firing_ns[b * kBlockChannels + c] = static_cast<std::int64_t>(b) * block_ns + std::llround(firing[c] * 1000.0);
      s.beam[b * kBlockChannels + c] = static_cast<std::uint16_t>(c % 16);
    }
  }
  const double deg = std::numbers::pi / 180.0;
  for (std::size_t i = 0; i < angles.elevation_deg.size(); ++i) {
    s.beams.push_back({angles.elevation_deg[i] * deg, angles.azimuth_deg[i] * deg, 0.0, 0.0,
                       robosense_lens_offset_m(model)});
  }
  const double unit = robosense_distance_unit_m(model);
  s.max_range_m = 0xFFFE * unit;  // 0xFFFF means no return
  s.encode = [unit](const SpinningPacket& in, std::span<std::uint8_t> out) {
    RoboSenseMsop p;
    p.time_ns = in.time_ns;
    copy_blocks(in, unit, p.blocks);
    encode_robosense_msop(RoboSenseModel::rs16, p, out.first<kRoboSenseMsopSize>());
  };
  s.calibration_file = "RS16.csv";
  s.calibration_text = format_robosense_angle_csv(angles);
  return s;
}

}  // namespace adit::sim
