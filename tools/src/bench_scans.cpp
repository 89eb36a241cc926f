#include "bench_scans.hpp"

#include <algorithm>
#include <numbers>
#include <random>

#include <Eigen/Geometry>

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

// Scan k's sensor turned by spin_k = spin_k-1 + U(±spin_deg) about its z:
// its points are seen from Rz(spin_k), p' = Rz(spin_k)ᵀ·p.
void spin(std::vector<BenchScan>& scans, double spin_deg, unsigned seed, std::size_t from) {
  if (spin_deg <= 0.0) return;
  std::mt19937 rng(seed);
  const double step = spin_deg * std::numbers::pi / 180.0;
  std::uniform_real_distribution<double> turn(-step, step);
  double yaw = 0.0;
  for (std::size_t k = std::max<std::size_t>(from, 1); k < scans.size(); ++k) {
    yaw += turn(rng);
    scans[k].spin_rad = yaw;
    const Eigen::Matrix3f to_sensor = Eigen::AngleAxisf(static_cast<float>(-yaw), Eigen::Vector3f::UnitZ()).toRotationMatrix();
    for (Eigen::Vector3f& p : scans[k].points) p = to_sensor * p;
  }
}

std::vector<BenchScan> load(const BenchInput& input) {
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

}  // namespace

std::vector<BenchScan> load_bench_scans(const BenchInput& input) {
  std::vector<BenchScan> scans = load(input);
  spin(scans, input.spin_deg, input.spin_seed, input.spin_from);
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
