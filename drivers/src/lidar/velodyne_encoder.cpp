#include "adit/drivers/lidar/velodyne_encoder.hpp"

#include <algorithm>

namespace adit::drivers {

void encode_velodyne_packet(VelodyneModel model, const VelodyneDataPacket& packet,
                            std::span<std::uint8_t, kVelodyneDataPacketSize> out) {
  std::fill(out.begin(), out.end(), std::uint8_t{0});
  const std::size_t per_group = velodyne_blocks_per_group(model);
  for (std::size_t b = 0; b < VelodyneDecoder::kBlocks; ++b) {
    std::uint8_t* block = out.data() + b * 100;
    // VLS-128 banks are flagged FFEE, FFDD, FFCC, FFBB; every other model FFEE.
    const auto flag = static_cast<std::uint16_t>(per_group == 1 ? 0xFFEE : 0xFFEE - 0x11 * (b % 4));
    block[0] = static_cast<std::uint8_t>(flag >> 8);
    block[1] = static_cast<std::uint8_t>(flag);
    const VelodyneBlock& in = packet.blocks[b];
    block[2] = static_cast<std::uint8_t>(in.azimuth);
    block[3] = static_cast<std::uint8_t>(in.azimuth >> 8);
    for (std::size_t c = 0; c < VelodyneDecoder::kChannels; ++c) {
      std::uint8_t* m = block + 4 + 3 * c;
      m[0] = static_cast<std::uint8_t>(in.distance[c]);
      m[1] = static_cast<std::uint8_t>(in.distance[c] >> 8);
      m[2] = in.reflectivity[c];
    }
  }
  for (int i = 0; i < 4; ++i) out[1200 + i] = static_cast<std::uint8_t>(packet.us_past_hour >> (8 * i));
  out[1204] = static_cast<std::uint8_t>(packet.mode);
  out[1205] = velodyne_product_id(model);
}

}  // namespace adit::drivers
