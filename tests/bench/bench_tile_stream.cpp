// Bandwidth of the tile stream for a given map growth, and the cost of coding.
//
// Scenario: a robot drives through a 4 m x 3 m mine tunnel at 1 m/s; the map
// (5 cm voxels, surfaces with 1 cm roughness) grows by one metre of tunnel per
// second, i.e. 14 m^2 of new surface = 5 600 points/s. Every second the tile
// holding the new metre has changed and goes out whole (20 m tiles: the
// frontier tile grows from 0 to 112 000 points). Reported per simulated
// second: bytes on the wire (tile_chunk_t messages, LCM payload bytes), the
// same tiles as raw float x y z intensity (16 bytes/point, the baseline), and
// the ideal "send only new points raw" figure.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "adit/protocol/tile_codec.hpp"
#include "adit/tile_chunk_t.hpp"

namespace {

using adit::protocol::MapPoint;

// Points of tunnel metre `m` (x in [m, m+1)) on the floor, ceiling and walls.
void add_metre(int m, std::vector<MapPoint>& out, std::uint32_t& rng) {
  const auto rough = [&] {
    rng = rng * 1664525u + 1013904223u;
    return static_cast<int>((rng >> 16) % 21) * 0.001 - 0.010;
  };
  for (int i = 0; i < 20; ++i) {
    const double x = m + 0.025 + i * 0.05;
    for (int j = 0; j < 80; ++j) {  // floor and ceiling, 4 m wide
      const double y = -2.0 + 0.025 + j * 0.05;
      out.push_back({x, y, rough(), static_cast<float>(40 + j % 30), 0});
      out.push_back({x, y, 3.0 + rough(), static_cast<float>(60 + j % 20), 0});
    }
    for (int k = 0; k < 60; ++k) {  // walls, 3 m high
      const double z = 0.025 + k * 0.05;
      out.push_back({x, -2.0 + rough(), z, static_cast<float>(k), 0});
      out.push_back({x, 2.0 + rough(), z, static_cast<float>(k + 5), 0});
    }
  }
}

std::size_t wire_bytes(const std::vector<std::uint8_t>& blob) {
  std::size_t total = 0;
  const std::int32_t n = adit::protocol::chunk_count(blob.size());
  for (std::int32_t i = 0; i < n; ++i) {
    adit::tile_chunk_t m;
    m.payload_id = "drone-01";
    m.session_id = "20260101-120000";
    const auto piece = adit::protocol::chunk_of(blob, i);
    m.size = static_cast<std::int32_t>(piece.size());
    m.data.assign(piece.begin(), piece.end());
    total += static_cast<std::size_t>(m.getEncodedSize()) + 8 + 16;  // + LCM header and channel name
  }
  return total;
}

void BM_TileStreamTunnel(benchmark::State& state) {
  const int seconds = 60;  // three 20 m tiles
  const adit::protocol::TileParams params;
  // Arg 1: points in random order, as a voxel hash map may hand them over
  // (the worst case for compression); arg 0: in scan order.
  const bool shuffled = state.range(0) != 0;
  std::mt19937 order(3);
  double wire = 0, raw = 0, new_raw = 0;
  std::size_t points_total = 0;
  for (auto _ : state) {
    wire = raw = new_raw = 0;
    std::uint32_t rng = 1;
    std::vector<MapPoint> tile;
    for (int s = 0; s < seconds; ++s) {
      if (s % 20 == 0) tile.clear();  // the robot entered the next tile
      const std::size_t before = tile.size();
      add_metre(s, tile, rng);
      const auto key = adit::protocol::tile_of(s + 0.5, 0.0, 0.5, params.tile_size_m);
      if (shuffled) std::shuffle(tile.begin(), tile.end(), order);
      const auto blob = adit::protocol::encode_tile(key, tile, params);
      wire += static_cast<double>(wire_bytes(blob));
      raw += 16.0 * static_cast<double>(tile.size());
      new_raw += 16.0 * static_cast<double>(tile.size() - before);
      points_total += tile.size();
    }
    benchmark::DoNotOptimize(wire);
  }
  state.counters["wire_bytes_per_s"] = wire / seconds;
  state.counters["raw_whole_tiles_bytes_per_s"] = raw / seconds;
  state.counters["raw_new_points_bytes_per_s"] = new_raw / seconds;
  state.counters["new_points_per_s"] = new_raw / 16.0 / seconds;
  state.counters["ratio_raw_over_wire"] = raw / wire;
  state.counters["encoded_points_per_s"] =
      benchmark::Counter(static_cast<double>(points_total), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_TileStreamTunnel)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
