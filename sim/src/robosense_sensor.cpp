// The RS-16 as a SpinningSensor: the decoder's firing table (single return:
// two 16-laser sequences per block), the nominal angles (written as
// RS16.csv), the MSOP encoder.
#include <cmath>
#include <numbers>

#include "adit/drivers/lidar/robosense_encoder.hpp"
#include "adit/sim/spinning_lidar.hpp"

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
  s.packet_period_ns = static_cast<std::int64_t>(kBlocks) * block_ns;
  const auto firing = robosense_firing_us(model);
  for (std::size_t b = 0; b < kBlocks; ++b) {
    for (std::size_t c = 0; c < kChannels; ++c) {
      s.firing_ns[b * kChannels + c] = static_cast<std::int64_t>(b) * block_ns + std::llround(firing[c] * 1000.0);
      s.beam[b * kChannels + c] = static_cast<std::uint16_t>(c % 16);
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
    for (std::size_t b = 0; b < kBlocks; ++b) {
      p.blocks[b].azimuth = in.azimuth[b];
      for (std::size_t c = 0; c < kChannels; ++c) {
        const double r = in.range_m[b * kChannels + c];
        p.blocks[b].distance[c] = static_cast<std::uint16_t>(r > 0 ? std::lround(r / unit) : 0);
        p.blocks[b].reflectivity[c] = in.reflectivity[b * kChannels + c];
      }
    }
    encode_robosense_msop(RoboSenseModel::rs16, p, out.first<kRoboSenseMsopSize>());
  };
  s.calibration_file = "RS16.csv";
  s.calibration_text = format_robosense_angle_csv(angles);
  return s;
}

}  // namespace adit::sim
