#pragma once
// A finished session's scans again, from its raw recording (lidar.pcap,
// decoded with drivers/ by the model and calibration in its config.yaml), each
// as a RangeImage with the sensor's poses over it from map_trajectory.tum
// (a pose per scan start, interpolated: slam/trajectory_interpolate.hpp). This is what
// the moving-object pass (see_through.hpp) reads: the map keeps one point per
// voxel and no per-point times once tiles are spilled (docs/PRODUCTS.md
// "Rays"), the recording keeps every return with its firing time.

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>

#include <Eigen/Geometry>

#include "adit/products/see_through.hpp"
#include "adit/slam/trajectory.hpp"

namespace adit::products {

struct SessionScanStats {
  std::size_t scans = 0;           // decoded
  std::size_t used = 0;            // handed over (every scan_step-th with poses over its whole sweep)
  std::string skipped_because;     // non-empty: nothing could be read (no recording, no rings), and why
};

// Calls `on_scan` for every `scan_step`-th scan of SESSION_DIR/lidar.pcap that
// map_trajectory.tum covers. `body_poses` are the map's body poses (stamps:
// scan starts), `body_to_sensor` the LiDAR's extrinsics. A session without a
// recording, or a sensor without rings (Livox), returns with
// skipped_because set; an unreadable configuration or capture throws
// adit::InputError naming the file.
SessionScanStats for_each_session_scan(const std::filesystem::path& session_dir, const slam::Trajectory& body_poses,
                                       const Eigen::Isometry3d& body_to_sensor, int scan_step,
                                       const std::function<void(const RangeImage&, const ScanPoses&)>& on_scan);

}  // namespace adit::products
