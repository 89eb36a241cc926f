#include "bench_scans.hpp"

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/decode_stream.hpp"
#include "adit/drivers/lidar/registry.hpp"
#include "adit/drivers/lidar/scan_directory.hpp"
#include "adit/drivers/pcap_reader.hpp"

namespace adit::tools {
namespace {

BenchScan to_bench_scan(const drivers::LidarScan& scan, bool timed) {
  BenchScan out;
  out.stamp_ns = scan.start_time_ns;
  out.points.reserve(scan.points.size());
  for (const auto& p : scan.points) {
    out.points.emplace_back(p.x, p.y, p.z);
    if (timed) out.times_s.push_back(1e-9F * static_cast<float>(p.time_offset_ns));
  }
  return out;
}

}  // namespace

std::vector<BenchScan> load_bench_scans(const BenchInput& input) {
  std::vector<BenchScan> scans;
  const auto full = [&] { return input.max_scans > 0 && scans.size() >= input.max_scans; };
  if (!input.scans_dir.empty()) {
    drivers::ScanDirectorySource source(input.scans_dir);
    drivers::LidarScan scan;
    while (!full() && source.next(scan)) scans.push_back(to_bench_scan(scan, false));
    return scans;
  }
  const drivers::LidarFamily* family = drivers::lidar_family_of_model(input.model);
  if (family == nullptr) throw InputError(input.pcap, "--model", "unknown LiDAR model '" + input.model + "'");
  const auto decoder = family->make_decoder(input.model, input.calibration);
  drivers::ScanAssembler assembler(drivers::assembler_config_for(*decoder, 0, 0.0F));
  drivers::DecodeStream stream(*decoder, assembler, [&](drivers::LidarScan& scan) {
    if (!full() && scan.stats.complete) scans.push_back(to_bench_scan(scan, true));
  });
  drivers::PcapReader reader(input.pcap);
  drivers::UdpDatagram d;
  while (!full() && reader.next(d))
    if (d.dst_port == decoder->default_port()) stream.push(d.payload, d.capture_time_ns);
  return scans;
}

}  // namespace adit::tools
