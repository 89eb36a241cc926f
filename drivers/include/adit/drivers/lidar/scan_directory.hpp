#pragma once
// Scans from a directory of point-cloud files, for datasets that have no
// packets: binary or ascii PCD (x y z [intensity]) and KITTI velodyne .bin.
// Files are taken in name order; scan i starts at i × period on the sensor
// clock (these formats carry no time), with every point's time offset 0.

#include <cstdint>
#include <filesystem>
#include <vector>

#include "adit/drivers/lidar/point.hpp"
#include "adit/drivers/lidar/scan_files.hpp"

namespace adit::drivers {

class ScanDirectorySource {
 public:
  // Throws adit::InputError when `dir` is not a directory or holds no scans.
  explicit ScanDirectorySource(const std::filesystem::path& dir, std::int64_t period_ns = 100'000'000);

  // Reads the next file into `scan` (its storage is reused); false after the last.
  // A damaged file throws adit::InputError naming it; the next call moves on to the file after it.
  bool next(LidarScan& scan);

  std::size_t size() const { return files_.size(); }
  const std::vector<std::filesystem::path>& files() const { return files_; }

 private:
  std::vector<std::filesystem::path> files_;
  std::int64_t period_ns_;
  std::size_t index_ = 0;
  std::vector<CloudPoint> cloud_;
};

}  // namespace adit::drivers
