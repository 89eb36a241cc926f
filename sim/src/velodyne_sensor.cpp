// The VLP-16 as a SpinningSensor: the decoder's firing table, the nominal
// calibration (written as VLP16.yaml), the Velodyne packet encoder.
#include <cmath>

#include "adit/drivers/lidar/velodyne_encoder.hpp"
#include "adit/sim/spinning_lidar.hpp"
#include "block_packet.hpp"

namespace adit::sim {

SpinningSensor velodyne_vlp16_sensor() {
  using namespace adit::drivers;
  const VelodyneModel model = VelodyneModel::vlp16;
  const VelodyneCalibration calibration = velodyne_nominal_calibration(model);
  SpinningSensor s;
  s.model = "VLP-16";
  s.port = kVelodyneDataPort;
  s.packet_size = kVelodyneDataPacketSize;
  s.packet_period_ns = velodyne_packet_period_ns(model, VelodyneReturnMode::strongest);
  const std::size_t per_group = velodyne_blocks_per_group(model);
  for (std::size_t b = 0; b < s.blocks; ++b) {
    for (std::size_t c = 0; c < kBlockChannels; ++c) {
      const VelodyneFiring f = velodyne_firing(model, b % per_group, c);
      s.firing_ns[b * kBlockChannels + c] = static_cast<std::int64_t>(b / per_group) * velodyne_group_ns(model) + f.time_ns;
      s.beam[b * kBlockChannels + c] = f.laser;
    }
  }
  for (const VelodyneLaser& l : calibration.lasers) {
    // θ = azimuth − rotational correction (the decoder's convention).
    s.beams.push_back({l.vert_correction, -l.rot_correction, l.vert_offset_correction, l.horiz_offset_correction, 0.0});
  }
  const double unit = calibration.distance_resolution_m;
  s.max_range_m = 0xFFFF * unit;
  s.encode = [unit](const SpinningPacket& in, std::span<std::uint8_t> out) {
    VelodyneDataPacket p;
    p.us_past_hour = static_cast<std::uint32_t>((in.time_ns / 1000) % 3'600'000'000LL);
    copy_blocks(in, unit, p.blocks);
    encode_velodyne_packet(VelodyneModel::vlp16, p, out.first<kVelodyneDataPacketSize>());
  };
  s.calibration_file = "VLP16.yaml";
  s.calibration_text = format_velodyne_calibration(calibration);
  return s;
}

}  // namespace adit::sim
