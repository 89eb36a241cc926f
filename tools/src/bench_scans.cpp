#include "bench_scans.hpp"

#include <algorithm>

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
    if (timed) out.time_offsets_ns.push_back(p.time_offset_ns);
  }
  return out;
}

}  // namespace

std::vector<BenchScan> load_bench_scans(const BenchInput& input) {
  std::vector<BenchScan> scans;
  const auto full = [&] { return input.max_scans > 0 && scans.size() >= input.max_scans; };
  std::size_t seen = 0;
  const auto kept = [&] { return seen++ % std::max<std::size_t>(input.every, 1) == 0; };
  if (!input.scans_dir.empty()) {
    drivers::ScanDirectorySource source(input.scans_dir);
    drivers::LidarScan scan;
    while (!full() && source.next(scan))
      if (kept()) scans.push_back(to_bench_scan(scan, false));
    return scans;
  }
  const drivers::LidarFamily* family = drivers::lidar_family_of_model(input.model);
  if (family == nullptr) throw InputError(input.pcap, "--model", "unknown LiDAR model '" + input.model + "'");
  const auto decoder = family->make_decoder(input.model, input.calibration);
  drivers::ScanAssembler assembler(drivers::assembler_config_for(*decoder, 0, 0.0F));
  drivers::DecodeStream stream(*decoder, assembler, [&](drivers::LidarScan& scan) {
    if (!full() && scan.stats.complete && kept()) scans.push_back(to_bench_scan(scan, true));
  });
  drivers::PcapReader reader(input.pcap);
  drivers::UdpDatagram d;
  while (!full() && reader.next(d))
    if (d.dst_port == decoder->default_port()) stream.push(d.payload, d.capture_time_ns);
  return scans;
}

void to_lidar_scan(const BenchScan& scan, drivers::LidarScan& out) {
  out.clear();
  out.start_time_ns = scan.stamp_ns;
  const bool timed = scan.time_offsets_ns.size() == scan.points.size();
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    drivers::LidarPoint p;
    p.x = scan.points[i].x();
    p.y = scan.points[i].y();
    p.z = scan.points[i].z();
    p.range_m = scan.points[i].norm();
    p.time_offset_ns = timed ? scan.time_offsets_ns[i] : 0;
    out.points.push_back(p);
  }
  out.stats.complete = true;
}

}  // namespace adit::tools
