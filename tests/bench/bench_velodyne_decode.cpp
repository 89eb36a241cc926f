// Velodyne decoding throughput, points per second on one core, on the real
// VLP-16 dual and VLP-32C captures, with a baseline in the same run: the same
// packets through a naive decoder that evaluates sin/cos per point (what the
// decoder's precomputed per-laser and per-0.01° tables replace). The goal is
// ≥ 50 M points/s (20× a 128-beam sensor's data rate).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <string>

#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/velodyne.hpp"
#include "adit/drivers/lidar/velodyne_encoder.hpp"
#include "adit/drivers/pcap_reader.hpp"
#include "shared_data.hpp"

namespace {
using namespace adit::drivers;

struct Capture {
  VelodyneModel model;
  VelodyneCalibration calibration;
  std::vector<std::vector<std::uint8_t>> packets;
};

Capture load(const std::string& folder, VelodyneModel model, const std::string& yaml) {
  Capture c{model, {}, {}};
  const auto root = adit::test::shared_data_dir();
  if (!root) return c;
  const auto dir = *root / "lidar" / folder;
  c.calibration = load_velodyne_calibration(dir / yaml);
  PcapReader reader(dir / "capture.pcap");
  UdpDatagram d;
  while (reader.next(d)) {
    if (d.payload.size() == kVelodyneDataPacketSize) c.packets.emplace_back(d.payload.begin(), d.payload.end());
  }
  return c;
}

const Capture& capture(int which) {
  static const Capture vlp16 = load("velodyne-vlp16-dual", VelodyneModel::vlp16, "VLP16.yaml");
  static const Capture vlp32 = load("velodyne-vlp32c", VelodyneModel::vlp32c, "VLP32.yaml");
  return which == 0 ? vlp16 : vlp32;
}

// The baseline: the same packet layout and azimuth interpolation, with the
// trigonometry evaluated per point in double precision.
std::size_t decode_naive(const Capture& c, std::span<const std::uint8_t> p, std::vector<DecodedPoint>& out) {
  const bool dual = p[1204] == 0x39;
  const bool vlp16 = c.model == VelodyneModel::vlp16;
  const double resolution = vlp16 ? 0.002 : 0.004;
  std::size_t n = 0;
  for (std::size_t b = 0; b < 12; ++b) {
    const std::uint8_t* block = p.data() + b * 100;
    const double azimuth = (block[2] | block[3] << 8) * 0.01;
    const std::size_t next = std::min<std::size_t>(b + (dual ? 2 : 1), 11);
    double step = ((p[next * 100 + 2] | p[next * 100 + 3] << 8) * 0.01) - azimuth;
    if (step < 0) step += 360.0;
    for (std::size_t ch = 0; ch < 32; ++ch) {
      const std::uint16_t raw = static_cast<std::uint16_t>(block[4 + 3 * ch] | block[5 + 3 * ch] << 8);
      if (raw == 0) continue;
      const std::size_t laser = vlp16 ? ch % 16 : ch;
      const double t = vlp16 ? ((ch / 16) * 55.296 + (ch % 16) * 2.304) / 110.592 : (ch / 2) * 2.304 / 55.296;
      const VelodyneLaser& l = c.calibration.lasers[laser];
      const double distance = raw * resolution + l.dist_correction;
      const double theta = (azimuth + step * t) * std::numbers::pi / 180.0 - l.rot_correction;
      const double xy = distance * std::cos(l.vert_correction);
      DecodedPoint& q = out[n++];
      q.point.x = static_cast<float>(xy * std::cos(theta));
      q.point.y = static_cast<float>(-xy * std::sin(theta));
      q.point.z = static_cast<float>(distance * std::sin(l.vert_correction));
      q.point.intensity = block[6 + 3 * ch];
      q.point.range_m = static_cast<float>(distance);
    }
  }
  return n;
}

void BM_Decode(benchmark::State& state) {
  const Capture& c = capture(static_cast<int>(state.range(0)));
  if (c.packets.empty()) {
    state.SkipWithError("shared data not found (set ADIT_SHARED_DATA)");
    return;
  }
  VelodyneDecoder decoder(c.model, c.calibration);
  std::int64_t points = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    const DecodedPacket d = decoder.decode(c.packets[i], 1'700'000'000'000'000'000);
    benchmark::DoNotOptimize(d.points.data());
    points += static_cast<std::int64_t>(d.points.size());
    i = i + 1 == c.packets.size() ? 0 : i + 1;
  }
  state.SetItemsProcessed(points);
}

void BM_DecodeNaiveBaseline(benchmark::State& state) {
  const Capture& c = capture(static_cast<int>(state.range(0)));
  if (c.packets.empty()) {
    state.SkipWithError("shared data not found (set ADIT_SHARED_DATA)");
    return;
  }
  std::vector<DecodedPoint> out(VelodyneDecoder::kMaxPoints);
  std::int64_t points = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t n = decode_naive(c, c.packets[i], out);
    benchmark::DoNotOptimize(out.data());
    points += static_cast<std::int64_t>(n);
    i = i + 1 == c.packets.size() ? 0 : i + 1;
  }
  state.SetItemsProcessed(points);
}

void BM_DecodeAndAssemble(benchmark::State& state) {
  const Capture& c = capture(static_cast<int>(state.range(0)));
  if (c.packets.empty()) {
    state.SkipWithError("shared data not found (set ADIT_SHARED_DATA)");
    return;
  }
  VelodyneDecoder decoder(c.model, c.calibration);
  const auto mode = velodyne_return_mode_from_packet(c.packets[0]).value_or(VelodyneReturnMode::strongest);
  ScanAssembler assembler(assembler_config_for(decoder, velodyne_packet_period_ns(c.model, mode), 0.0F));
  std::int64_t points = 0;
  std::size_t i = 0;
  std::int64_t host = 1'700'000'000'000'000'000;
  for (auto _ : state) {
    const DecodedPacket d = decoder.decode(c.packets[i], host += 500'000);
    assembler.add(d);
    points += static_cast<std::int64_t>(d.points.size());
    i = i + 1 == c.packets.size() ? 0 : i + 1;
  }
  state.SetItemsProcessed(points);
}

// VLS-128 (no real capture is public): 256 synthetic strongest-return packets written by the
// encoder (3 firing sequences x 128 lasers each, every laser returning), and dual packets.
void BM_DecodeVls128Synthetic(benchmark::State& state) {
  const bool dual = state.range(0) == 1;
  VelodyneCalibration calibration;
  for (int l = 0; l < 128; ++l) {
    VelodyneLaser laser;
    laser.laser_id = l;
    laser.vert_correction = (l - 64) * 0.003;
    laser.rot_correction = (l % 8 - 4) * 0.01;
    calibration.lasers.push_back(laser);
  }
  std::vector<std::vector<std::uint8_t>> packets;
  for (int k = 0; k < 256; ++k) {
    VelodyneDataPacket p;
    p.us_past_hour = static_cast<std::uint32_t>(1000 + k * (dual ? 53 : 160));
    p.mode = dual ? VelodyneReturnMode::dual : VelodyneReturnMode::strongest;
    for (std::size_t b = 0; b < 12; ++b) {
      const std::size_t group = dual ? 0 : b / 4;
      p.blocks[b].azimuth = static_cast<std::uint16_t>((k * (dual ? 20 : 60) + group * 20) % 36000);
      for (std::size_t c = 0; c < 32; ++c) {
        p.blocks[b].distance[c] = static_cast<std::uint16_t>(dual && b >= 8 ? 0 : 2000 + c + (dual ? b % 2 : 0) * 7);
        p.blocks[b].reflectivity[c] = static_cast<std::uint8_t>(c);
      }
    }
    packets.emplace_back(kVelodyneDataPacketSize);
    encode_velodyne_packet(VelodyneModel::vls128, p, std::span<std::uint8_t, kVelodyneDataPacketSize>(packets.back()));
    if (dual) {  // the encoder writes single-return bank flags; a dual packet pairs them
      for (std::size_t b = 0; b < 8; ++b) packets.back()[b * 100 + 1] = static_cast<std::uint8_t>(0xEE - 0x11 * (b / 2));
    }
  }
  VelodyneDecoder decoder(VelodyneModel::vls128, calibration);
  std::int64_t points = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    const DecodedPacket d = decoder.decode(packets[i], 1'700'000'000'000'000'000);
    if (d.status != PacketStatus::ok) state.SkipWithError("a synthetic VLS-128 packet did not decode");
    benchmark::DoNotOptimize(d.points.data());
    points += static_cast<std::int64_t>(d.points.size());
    i = i + 1 == packets.size() ? 0 : i + 1;
  }
  state.SetItemsProcessed(points);
}

BENCHMARK(BM_DecodeVls128Synthetic)->Arg(0)->Arg(1)->ArgName("single_dual");
BENCHMARK(BM_Decode)->Arg(0)->Arg(1)->ArgName("vlp16dual_vlp32c");
BENCHMARK(BM_DecodeNaiveBaseline)->Arg(0)->Arg(1)->ArgName("vlp16dual_vlp32c");
BENCHMARK(BM_DecodeAndAssemble)->Arg(0)->Arg(1)->ArgName("vlp16dual_vlp32c");

// Prints the speed-up over the baseline measured in this run.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs) {
      const auto it = run.counters.find("items_per_second");
      if (it != run.counters.end()) rates_[run.benchmark_name()] = it->second;
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    for (const char* arg : {"0", "1"}) {
      const std::string suffix = std::string("/vlp16dual_vlp32c:") + arg;
      const double fast = rates_["BM_Decode" + suffix];
      const double naive = rates_["BM_DecodeNaiveBaseline" + suffix];
      if (fast > 0 && naive > 0) {
        std::printf("%s: %.1f M points/s with tables vs %.1f M points/s naive: %.2fx\n",
                    arg[0] == '0' ? "VLP-16 dual" : "VLP-32C", fast / 1e6, naive / 1e6, fast / naive);
      }
    }
  }

 private:
  std::map<std::string, double> rates_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
