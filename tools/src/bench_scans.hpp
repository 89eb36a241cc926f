#pragma once
// Scans for benchmarks, loaded up front so that only odometry is timed: from
// a directory of PCD/KITTI files or decoded from a capture.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "adit/drivers/lidar/point.hpp"

namespace adit::tools {

struct BenchScan {
  std::int64_t stamp_ns = 0;
  std::vector<Eigen::Vector3f> points;
  std::vector<std::uint32_t> time_offsets_ns;  // per point after stamp_ns; empty when the source has none
  float time_s(std::size_t i) const { return 1e-9F * static_cast<float>(time_offsets_ns[i]); }
  double spin_rad = 0.0;  // the sensor's added turn about its z (BenchInput::spin_deg); its pose is the scan's times Rz(spin)
};

struct BenchInput {
  std::string scans_dir;
  std::string pcap;
  std::string model;
  std::string calibration;
  std::size_t max_scans = 0;  // 0 = all
  std::size_t every = 1;      // keep one scan in this many (the first, then every Nth): larger steps between scans
  // Turns the sensor about its z on top of its own motion, by a uniform
  // random step in ±spin_deg from one kept scan to the next (seeded): the
  // fast turns of a hand-held scanner put into real scans (0 = none).
  double spin_deg = 0.0;
  unsigned spin_seed = 1;
  std::size_t spin_from = 1;  // the first kept scan that turns: before it, tracking is under way

};

std::vector<BenchScan> load_bench_scans(const BenchInput& input);

// The scan as the drivers hand it to aditd's odometry (sensor frame; no
// intensities), into `out`'s storage.
void to_lidar_scan(const BenchScan& scan, drivers::LidarScan& out);

}  // namespace adit::tools
