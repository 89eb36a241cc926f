#pragma once
// Scans for benchmarks, loaded up front so that only odometry is timed: from
// a directory of PCD/KITTI files or decoded from a capture.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace adit::tools {

struct BenchScan {
  std::int64_t stamp_ns = 0;
  std::vector<Eigen::Vector3f> points;
  std::vector<float> times_s;  // empty when the source has no per-point times
};

struct BenchInput {
  std::string scans_dir;
  std::string pcap;
  std::string model;
  std::string calibration;
  std::size_t max_scans = 0;  // 0 = all
};

std::vector<BenchScan> load_bench_scans(const BenchInput& input);

}  // namespace adit::tools
