// Ouster decoding throughput, points per second on one core, on the real
// captures' packets held in memory (no I/O). Goal: >= 50 M points/s.
//
// Baseline in the same run: the same packets through a straightforward
// decoder that evaluates the manual's XYZ equations per point (sin/cos per
// pixel, no lookup table); the summary prints our speed-up over it.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "adit/drivers/lidar/ouster_decoder.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "shared_data.hpp"

namespace {

using namespace adit::drivers;

struct Capture {
  OusterMetadata metadata;
  std::vector<std::vector<std::uint8_t>> packets;
};

const Capture* load(const std::string& name) {
  static std::map<std::string, Capture> cache;
  if (const auto it = cache.find(name); it != cache.end()) return &it->second;
  const auto root = adit::test::shared_data_dir();
  if (!root) return nullptr;
  const auto dir = *root / "lidar/ouster";
  std::string pcap = name + ".pcap";
  std::string meta = name + ".json";
  if (name.starts_with("OS-1-128")) {
    pcap = name + "_lb_n3.pcap";
  }
  if (!std::filesystem::exists(dir / pcap)) return nullptr;
  Capture c;
  c.metadata = load_ouster_metadata(dir / meta);
  const std::size_t size = OusterPacketLayout::of(c.metadata).packet_bytes;
  PcapReader reader(dir / pcap);
  UdpDatagram d;
  while (reader.next(d))
    if (d.payload.size() == size) c.packets.emplace_back(d.payload.begin(), d.payload.end());
  return &cache.emplace(name, std::move(c)).first->second;
}

void BM_OusterDecode(benchmark::State& state, const std::string& name) {
  const Capture* c = load(name);
  if (c == nullptr) {
    state.SkipWithError("shared data not found (set ADIT_SHARED_DATA)");
    return;
  }
  OusterDecoder decoder(c->metadata);
  std::int64_t points = 0;
  for (auto _ : state) {
    for (const auto& p : c->packets) {
      const DecodedPacket out = decoder.decode(p, 0);
      benchmark::DoNotOptimize(out.points.data());
      points += static_cast<std::int64_t>(out.points.size());
    }
  }
  state.SetItemsProcessed(points);
  state.counters["packets/s"] = benchmark::Counter(
      static_cast<double>(state.iterations() * c->packets.size()), benchmark::Counter::kIsRate);
}

// The baseline: the manual's equations per point, no precomputation.
void BM_BaselineNaiveTrig(benchmark::State& state, const std::string& name) {
  const Capture* c = load(name);
  if (c == nullptr) {
    state.SkipWithError("shared data not found (set ADIT_SHARED_DATA)");
    return;
  }
  const OusterMetadata& m = c->metadata;
  const OusterPacketLayout layout = OusterPacketLayout::of(m);
  std::vector<DecodedPoint> out(static_cast<std::size_t>(layout.columns_per_packet * layout.pixels_per_column * 2));
  const double two_pi = 2 * std::numbers::pi;
  const double n = m.lidar_origin_to_beam_origin_mm;
  std::int64_t points = 0;
  for (auto _ : state) {
    for (const auto& p : c->packets) {
      std::size_t k = 0;
      for (int col = 0; col < layout.columns_per_packet; ++col) {
        const auto* column = layout.column(p.data(), col);
        const OusterColumnHeader h = read_column_header(layout, column);
        if (!h.valid || h.measurement_id >= m.columns_per_frame) continue;
        const double te = two_pi * (1.0 - static_cast<double>(h.measurement_id) / m.columns_per_frame);
        for (int row = 0; row < layout.pixels_per_column; ++row) {
          const OusterReturn r = read_return(layout.profile, layout.pixel(column, row), 0);
          if (r.range_mm == 0) continue;
          const double ta = -two_pi * m.beam_azimuth_deg[static_cast<std::size_t>(row)] / 360.0;
          const double phi = two_pi * m.beam_altitude_deg[static_cast<std::size_t>(row)] / 360.0;
          const double range = r.range_mm;
          const double x = (range - n) * std::cos(te + ta) * std::cos(phi) + n * std::cos(te);
          const double y = (range - n) * std::sin(te + ta) * std::cos(phi) + n * std::sin(te);
          const double z = (range - n) * std::sin(phi);
          DecodedPoint& dp = out[k++];
          dp.point.x = static_cast<float>(-x / 1000);
          dp.point.y = static_cast<float>(-y / 1000);
          dp.point.z = static_cast<float>((z + m.lidar_to_sensor[11]) / 1000);
          dp.point.intensity = r.reflectivity;
          dp.sensor_time_ns = static_cast<std::int64_t>(h.timestamp_ns);
        }
      }
      benchmark::DoNotOptimize(out.data());
      points += static_cast<std::int64_t>(k);
    }
  }
  state.SetItemsProcessed(points);
}

// Prints each capture's speed-up over the baseline after the usual table.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      const auto it = r.counters.find("items_per_second");
      if (it != r.counters.end()) rates_[r.benchmark_name()] = it->second.value;
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    for (const auto& [name, rate] : rates_) {
      const auto slash = name.find('/');
      if (!name.starts_with("BM_OusterDecode") || slash == std::string::npos) continue;
      if (name.ends_with("_stddev") || name.ends_with("_cv")) continue;  // ratios of spreads mean nothing
      const auto base = rates_.find("BM_BaselineNaiveTrig" + name.substr(slash));
      if (base == rates_.end() || base->second <= 0) continue;
      std::printf("%s: %.1f M points/s, %.1fx the per-point trig baseline (%.1f M points/s)\n",
                  name.substr(slash + 1).c_str(), rate / 1e6, rate / base->second, base->second / 1e6);
    }
  }

 private:
  std::map<std::string, double> rates_;
};

}  // namespace

int main(int argc, char** argv) {
  for (const std::string name : {"OS-1-32-G_v2.1.1_1024x10", "OS-0-128-U1_v2.3.0_1024x10", "OS-1-128_v2.3.0_1024x10"}) {
    benchmark::RegisterBenchmark(("BM_OusterDecode/" + name).c_str(), BM_OusterDecode, name);
    benchmark::RegisterBenchmark(("BM_BaselineNaiveTrig/" + name).c_str(), BM_BaselineNaiveTrig, name);
  }
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
