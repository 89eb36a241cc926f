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
};

struct BenchInput {
  std::string scans_dir;
  std::string pcap;
  std::string model;
  std::string calibration;
  std::size_t max_scans = 0;  // 0 = all
  std::size_t every = 1;      // keep one scan in this many (the first, then every Nth): larger steps between scans
};

std::vector<BenchScan> load_bench_scans(const BenchInput& input);

// The scan as the drivers hand it to aditd's odometry (sensor frame; no
// intensities), into `out`'s storage.
void to_lidar_scan(const BenchScan& scan, drivers::LidarScan& out);

}  // namespace adit::tools
