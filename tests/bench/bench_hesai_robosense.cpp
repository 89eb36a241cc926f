// Decoding throughput of the Hesai and RoboSense decoders, in points per second
// on one core (goal: 50 M points/s). Packets come from the real captures in
// ../shared/data when present, else from the synthetic builders. The baseline,
// measured in the same run, decodes the same XT32 packets the obvious way:
// sin/cos per point instead of the decoder's tables and angle-addition.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "../drivers/lidar_packet_builders.hpp"
#include "decode_rate.hpp"
#include "adit/drivers/lidar/hesai.hpp"
#include "adit/drivers/lidar/robosense.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "shared_data.hpp"

namespace adit::drivers {
namespace {

Packets capture_or(const char* relative, const std::vector<std::uint8_t>& synthetic) {
  Packets packets;
  if (const auto root = test::shared_data_dir(); root && std::filesystem::exists(*root / relative)) {
    PcapReader reader(*root / relative);
    UdpDatagram d;
    while (reader.next(d)) packets.emplace_back(d.payload.begin(), d.payload.end());
  }
  if (packets.empty()) packets.assign(64, synthetic);
  return packets;
}

HesaiAngleCorrection angles(int lasers) {
  HesaiAngleCorrection a;
  for (int c = 0; c < lasers; ++c) {
    a.elevation_deg.push_back(15.0F - 30.0F * static_cast<float>(c) / static_cast<float>(lasers));
    a.azimuth_deg.push_back(c % 2 == 0 ? 0.1F : -0.1F);
  }
  return a;
}

const test::HesaiLayout& layout(const char* model) {
  static const auto layouts = test::hesai_layouts();
  for (const auto& l : layouts) {
    if (l.model == model) return l;
  }
  return layouts[1];
}

void BM_HesaiXT32(benchmark::State& state) {
  static const Packets packets = capture_or("lidar/hesai-xt32/capture.pcap", test::hesai_packet(layout("PandarXT32")));
  HesaiDecoder decoder(HesaiModel::pandar_xt32, angles(32));
  run_decode(state, decoder, packets);
}

void BM_HesaiQT64(benchmark::State& state) {
  static const Packets packets = capture_or("lidar/hesai-qt64/capture.pcap", test::hesai_packet(layout("PandarQT64")));
  HesaiDecoder decoder(HesaiModel::pandar_qt64, angles(64));
  run_decode(state, decoder, packets);
}

void BM_HesaiQT128Synthetic(benchmark::State& state) {
  const Packets packets(64, test::hesai_packet(layout("PandarQT128")));
  HesaiDecoder decoder(HesaiModel::pandar_qt128, angles(128));
  run_decode(state, decoder, packets);
}

void BM_RoboSenseHelios16P(benchmark::State& state) {
  static const Packets packets = capture_or("lidar/robosense-helios16p/capture.pcap", test::robosense_msop(true, 0, 20));
  RoboSenseAngles a;
  for (int i = 0; i < 16; ++i) a.elevation_deg.push_back(-15.0F + 2.0F * i), a.azimuth_deg.push_back(i % 2 ? 3.6F : -4.0F);
  RoboSenseDecoder decoder(RoboSenseModel::helios16p, a, RoboSenseReturnMode::single);
  run_decode(state, decoder, packets);
}

// Baseline: the XT32 packets decoded field by field with trigonometry per point
// (and no precomputed firing table), into the same preallocated output.
void BM_BaselineXT32NaiveTrig(benchmark::State& state) {
  static const Packets packets = capture_or("lidar/hesai-xt32/capture.pcap", test::hesai_packet(layout("PandarXT32")));
  const auto a = angles(32);
  std::vector<DecodedPoint> out(256);
  std::size_t points = 0;
  constexpr double kDeg = std::numbers::pi / 180.0;
  for (auto _ : state) {
    for (const auto& p : packets) {
      if (p.size() != 1080) continue;
      const double unit = p[9] * 0.001;
      std::size_t n = 0;
      for (int b = 0; b < 8; ++b) {
        const std::size_t at = 12 + static_cast<std::size_t>(b) * 130;
        const double az = (p[at] | (p[at + 1] << 8)) * 0.01;
        for (int c = 0; c < 32; ++c) {
          const std::size_t u = at + 2 + static_cast<std::size_t>(c) * 4;
          const unsigned raw = p[u] | (p[u + 1] << 8);
          if (raw == 0) continue;
          const double r = raw * unit;
          const double el = a.elevation_deg[c] * kDeg;
          const double beam = (az + a.azimuth_deg[c]) * kDeg;
          DecodedPoint& d = out[n++];
          d.point.x = static_cast<float>(r * std::cos(el) * std::cos(beam));
          d.point.y = static_cast<float>(-r * std::cos(el) * std::sin(beam));
          d.point.z = static_cast<float>(r * std::sin(el));
          d.point.intensity = p[u + 2];
          d.point.range_m = static_cast<float>(r);
          d.sensor_time_ns = 5632 - 50000 * ((7 - b) / 2) + 368 + 1512 * c;
        }
      }
      points += n;
      benchmark::DoNotOptimize(out.data());
    }
  }
  state.counters["points_per_s"] = benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsRate);
}

BENCHMARK(BM_HesaiXT32);
BENCHMARK(BM_BaselineXT32NaiveTrig);
BENCHMARK(BM_HesaiQT64);
BENCHMARK(BM_HesaiQT128Synthetic);
BENCHMARK(BM_RoboSenseHelios16P);

}  // namespace
}  // namespace adit::drivers

BENCHMARK_MAIN();
