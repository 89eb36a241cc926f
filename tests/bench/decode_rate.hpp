#pragma once
// A LiDAR decoder's rate over a set of packets: points and packets per
// second of CPU on one core, the figure the drivers' 50 M points/s goal is
// read against.

#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "adit/drivers/lidar/decoder.hpp"

namespace adit::drivers {

using Packets = std::vector<std::vector<std::uint8_t>>;

inline void run_decode(benchmark::State& state, LidarDecoder& decoder, const Packets& packets) {
  std::size_t points = 0;
  for (auto _ : state) {
    for (const auto& p : packets) {
      const DecodedPacket out = decoder.decode(p, 0);
      points += out.points.size();
      benchmark::DoNotOptimize(out.points.data());
    }
  }
  state.counters["points_per_s"] = benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsRate);
  state.counters["packets_per_s"] = benchmark::Counter(
      static_cast<double>(packets.size()) * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

}  // namespace adit::drivers
