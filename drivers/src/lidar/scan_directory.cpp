#include "adit/drivers/lidar/scan_directory.hpp"

#include <algorithm>
#include <cmath>

#include "adit/common/error.hpp"

namespace adit::drivers {

ScanDirectorySource::ScanDirectorySource(const std::filesystem::path& dir, std::int64_t period_ns)
    : period_ns_(period_ns) {
  if (!std::filesystem::is_directory(dir)) throw InputError(dir.string(), "", "not a directory");
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const auto ext = entry.path().extension();
    if (entry.is_regular_file() && (ext == ".pcd" || ext == ".bin")) files_.push_back(entry.path());
  }
  if (files_.empty()) throw InputError(dir.string(), "", "holds no .pcd or .bin scans");
  std::sort(files_.begin(), files_.end());
}

bool ScanDirectorySource::next(LidarScan& scan) {
  if (index_ >= files_.size()) return false;
  // Advance first: after a damaged file throws, the next call moves on to the following one.
  const std::size_t index = index_++;
  const std::filesystem::path& file = files_[index];
  if (file.extension() == ".bin") {
    read_kitti_bin(file, cloud_);
  } else {
    read_pcd(file, cloud_);
  }
  scan.clear();
  scan.points.reserve(cloud_.size());
  for (const CloudPoint& c : cloud_) {
    if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) continue;  // PCL's "no return"
    LidarPoint p;
    p.x = c.x;
    p.y = c.y;
    p.z = c.z;
    p.intensity = c.intensity;
    p.range_m = std::sqrt(c.x * c.x + c.y * c.y + c.z * c.z);
    scan.points.push_back(p);
  }
  scan.sensor_start_time_ns = static_cast<std::int64_t>(index) * period_ns_;
  scan.start_time_ns = scan.sensor_start_time_ns;
  scan.stats.packets = 0;
  scan.stats.complete = true;
  return true;
}

}  // namespace adit::drivers
