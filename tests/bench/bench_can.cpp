// candump parsing and signal decoding, in frames per second on one core,
// against a naive sscanf parser measured in the same run. Uses the RAV4 drive
// when ../shared/data is present, else a synthetic log of the same shape.

#include <benchmark/benchmark.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "adit/drivers/can/candump.hpp"
#include "adit/drivers/can/dbc.hpp"
#include "adit/drivers/can/decoder.hpp"
#include "shared_data.hpp"

namespace can = adit::drivers::can;

namespace {

constexpr std::string_view kWheelDbc =
    "BO_ 170 WHEEL_SPEEDS: 8 XXX\n"
    " SG_ WHEEL_SPEED_FR : 6|15@0+ (0.01,-67.67) [0|0] \"km/h\" X\n"
    " SG_ WHEEL_SPEED_FL : 22|15@0+ (0.01,-67.67) [0|0] \"km/h\" X\n"
    " SG_ WHEEL_SPEED_RR : 38|15@0+ (0.01,-67.67) [0|0] \"km/h\" X\n"
    " SG_ WHEEL_SPEED_RL : 54|15@0+ (0.01,-67.67) [0|0] \"km/h\" X\n";

struct Corpus {
  std::string text;
  std::vector<std::string> lines;
  std::vector<can::Frame> frames;
  std::string dbc_text;
  bool real = false;
};

const Corpus& corpus() {
  static const Corpus c = [] {
    Corpus out;
    const auto root = adit::test::shared_data_dir();
    const auto dir = root ? *root / "can/toyota-rav4-2017" : std::filesystem::path();
    if (root && std::filesystem::exists(dir / "drive.candump.log")) {
      std::ifstream in(dir / "drive.candump.log");
      for (std::string line; std::getline(in, line);) out.lines.push_back(line);
      std::ifstream dbc(dir / "toyota_rav4_2017.dbc");
      std::ostringstream s;
      s << dbc.rdbuf();
      out.dbc_text = s.str();
      out.real = true;
    } else {
      std::mt19937 rng(1);
      for (int i = 0; i < 135468; ++i) {
        can::Frame f;
        f.time_us = 46408'000'000 + i * 443;
        f.id = i % 27 == 0 ? 0xAA : rng() % 0x7FF;
        f.length = 8;
        for (int b = 0; b < 8; ++b) f.data[b] = static_cast<std::uint8_t>(rng());
        f.set_interface_name(i % 3 ? "can0" : "can1");
        out.lines.push_back(can::to_candump_line(f));
      }
      out.dbc_text = std::string(kWheelDbc);
    }
    for (const auto& line : out.lines) {
      can::Frame f;
      if (can::parse_candump_line(line, f) == can::LineError::none) out.frames.push_back(f);
    }
    for (const auto& line : out.lines) out.text += line + "\n";
    return out;
  }();
  return c;
}

void BM_ParseCandump(benchmark::State& state) {
  const Corpus& c = corpus();
  can::Frame f;
  for (auto _ : state) {
    for (const auto& line : c.lines) {
      benchmark::DoNotOptimize(can::parse_candump_line(line, f));
      benchmark::DoNotOptimize(f.data[0]);
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * c.lines.size()));
}

// The baseline: what one writes first, sscanf for the fields and per-byte hex.
void BM_BaselineSscanf(benchmark::State& state) {
  const Corpus& c = corpus();
  can::Frame f;
  for (auto _ : state) {
    for (const auto& line : c.lines) {
      long long sec = 0, usec = 0;
      char iface[16];
      char id_text[16];
      char data[140];
      data[0] = '\0';
      if (std::sscanf(line.c_str(), "(%lld.%lld) %15s %15[^#]#%139s", &sec, &usec, iface, id_text, data) < 4) continue;
      f.time_us = sec * 1'000'000 + usec;
      f.id = static_cast<std::uint32_t>(std::strtoul(id_text, nullptr, 16));
      f.set_interface_name(iface);
      std::size_t n = 0;
      for (const char* p = data; p[0] != '\0' && p[1] != '\0' && n < 8; p += 2) {
        unsigned byte = 0;
        std::sscanf(p, "%2x", &byte);
        f.data[n++] = static_cast<std::uint8_t>(byte);
      }
      f.length = static_cast<std::uint8_t>(n);
      benchmark::DoNotOptimize(f.data[0]);
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * c.lines.size()));
}

void decode_bench(benchmark::State& state, const can::Database& db, std::vector<std::string> wanted) {
  const Corpus& c = corpus();
  can::SignalDecoder decoder(db.messages, wanted);
  std::vector<double> values(decoder.slot_count());
  for (auto _ : state) {
    for (const can::Frame& f : c.frames) benchmark::DoNotOptimize(decoder.decode(f, values));
    benchmark::DoNotOptimize(values.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * c.frames.size()));
}

void BM_DecodeWheelSpeeds(benchmark::State& state) {
  decode_bench(state, can::parse_dbc(kWheelDbc, "wheel.dbc"), {});
}

void BM_DecodeWholeDbc(benchmark::State& state) {
  decode_bench(state, can::parse_dbc(corpus().dbc_text, "rav4.dbc"), {});
}

// Reading a file line by line, parsing and decoding the wheel speeds: what
// can-decode and a replay do per frame.
void BM_ReadParseDecode(benchmark::State& state) {
  const Corpus& c = corpus();
  const auto path = std::filesystem::temp_directory_path() / "adit-bench-can.log";
  {
    std::ofstream out(path);
    out << c.text;
  }
  const can::Database db = can::parse_dbc(kWheelDbc, "wheel.dbc");
  can::SignalDecoder decoder(db.messages);
  std::vector<double> values(decoder.slot_count());
  std::int64_t frames = 0;
  for (auto _ : state) {
    can::CandumpReader reader(path);
    can::Frame f;
    while (reader.next(f)) {
      benchmark::DoNotOptimize(decoder.decode(f, values));
      ++frames;
    }
  }
  state.SetItemsProcessed(frames);
  std::filesystem::remove(path);
}

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
    std::printf("input: %s, %zu lines\n", corpus().real ? "RAV4 drive (shared data)" : "synthetic log", corpus().lines.size());
    for (const auto& [name, rate] : rates_) std::printf("%-24s %7.2f M frames/s\n", name.c_str(), rate / 1e6);
    const auto ours = rates_.find("BM_ParseCandump");
    const auto base = rates_.find("BM_BaselineSscanf");
    if (ours != rates_.end() && base != rates_.end() && base->second > 0)
      std::printf("parser: %.1fx the sscanf baseline\n", ours->second / base->second);
  }

 private:
  std::map<std::string, double> rates_;
};

}  // namespace

BENCHMARK(BM_ParseCandump)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BaselineSscanf)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeWheelSpeeds)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecodeWholeDbc)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReadParseDecode)->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
