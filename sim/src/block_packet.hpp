#pragma once
// What the Velodyne, RoboSense and Hesai descriptions share: the 32-channel
// block of their packets and the copy of a SpinningPacket's returns into the
// blocks of the model's packet struct.

#include <cmath>
#include <cstdint>

#include "adit/sim/spinning_lidar.hpp"

namespace adit::sim {

inline constexpr std::size_t kBlockChannels = 32;

// A range in the model's distance unit; 0 (no return) stays 0.
inline std::uint16_t range_counts(double range_m, double unit_m) {
  return static_cast<std::uint16_t>(range_m > 0 ? std::lround(range_m / unit_m) : 0);
}

// The blocks of `in` into the packet's blocks (an array of structs with
// `azimuth`, `distance[32]` and `reflectivity[32]`).
template <class Blocks>
void copy_blocks(const SpinningPacket& in, double unit_m, Blocks& blocks) {
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    blocks[b].azimuth = in.azimuth[b];
    for (std::size_t c = 0; c < kBlockChannels; ++c) {
      blocks[b].distance[c] = range_counts(in.range_m[b * kBlockChannels + c], unit_m);
      blocks[b].reflectivity[c] = in.reflectivity[b * kBlockChannels + c];
    }
  }
}

}  // namespace adit::sim
