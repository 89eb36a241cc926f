// Livox decoding throughput, points per second on one core (goal: 50 M
// points/s), on synthetic packets written by the encoder (no real Livox capture
// is public): Mid-360 SDK2 cartesian-high packets of 96 points, Avia SDK1 dual
// packets of 48 x 2. Baseline in the same run: the same Mid-360 packets read
// with memcpy into the SDK's packed structs and nothing else.
#include <benchmark/benchmark.h>

#include <cstring>
#include <random>
#include <vector>

#include "decode_rate.hpp"
#include "adit/drivers/lidar/livox.hpp"
#include "adit/drivers/lidar/livox_encoder.hpp"

namespace adit::drivers {
namespace {

std::vector<LivoxRawPoint> random_points(std::mt19937& rng) {
  std::vector<LivoxRawPoint> pts(96);
  for (auto& p : pts) {
    p.x_mm = static_cast<std::int32_t>(rng() % 60'000) - 30'000;
    p.y_mm = static_cast<std::int32_t>(rng() % 60'000) - 30'000;
    p.z_mm = static_cast<std::int32_t>(rng() % 10'000) - 5'000;
    p.reflectivity = static_cast<std::uint8_t>(rng());
  }
  return pts;
}

Packets mid360_packets() {
  std::mt19937 rng(1);
  Packets out;
  for (int k = 0; k < 256; ++k) {
    const auto pts = random_points(rng);
    LivoxSdk2PointPacket in;
    in.time_ns = 1'700'000'000'000'000'000 + k * 480'000LL;
    in.time_interval = 4800;
    in.udp_cnt = static_cast<std::uint16_t>(k);
    in.points = pts;
    out.emplace_back(livox_sdk2_point_packet_bytes(pts.size()));
    encode_livox_sdk2_points(in, out.back());
  }
  return out;
}

Packets avia_packets() {
  std::mt19937 rng(2);
  Packets out;
  for (int k = 0; k < 256; ++k) {
    const auto pts = random_points(rng);
    out.emplace_back(kLivoxSdk1PointPacketBytes);
    encode_livox_sdk1_points(1'700'000'000'000'000'000 + k * 200'000LL, true,
                             std::span<const LivoxRawPoint, 96>(pts.data(), 96), out.back());
  }
  return out;
}

void BM_LivoxMid360(benchmark::State& state) {
  static const Packets packets = mid360_packets();
  LivoxDecoder decoder(LivoxModel::mid360);
  run_decode(state, decoder, packets);
}

void BM_LivoxAviaDual(benchmark::State& state) {
  static const Packets packets = avia_packets();
  LivoxDecoder decoder(LivoxModel::avia);
  run_decode(state, decoder, packets);
}

#pragma pack(push, 1)
struct SdkPoint {
  std::int32_t x, y, z;
  std::uint8_t reflectivity, tag;
};
#pragma pack(pop)

void BM_LivoxMid360MemcpyBaseline(benchmark::State& state) {
  static const Packets packets = mid360_packets();
  std::vector<SdkPoint> pts(96);
  std::size_t points = 0;
  for (auto _ : state) {
    for (const auto& p : packets) {
      std::memcpy(pts.data(), p.data() + kLivoxSdk2HeaderBytes, 96 * sizeof(SdkPoint));
      points += 96;
      benchmark::DoNotOptimize(pts.data());
    }
  }
  state.counters["points_per_s"] = benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsRate);
}

BENCHMARK(BM_LivoxMid360);
BENCHMARK(BM_LivoxAviaDual);
BENCHMARK(BM_LivoxMid360MemcpyBaseline);

}  // namespace
}  // namespace adit::drivers

BENCHMARK_MAIN();
