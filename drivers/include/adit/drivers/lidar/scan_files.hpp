#pragma once
// Point-cloud files of single scans: reading PCD (PCL's format, DATA ascii or
// binary) and KITTI velodyne .bin (float32 x y z reflectance per point), and
// writing a LidarScan with every point field as PCD or binary PLY.
// Readers throw adit::InputError naming the file and what is wrong.

#include <filesystem>
#include <vector>

#include "adit/drivers/lidar/point.hpp"

namespace adit::drivers {

struct CloudPoint {
  float x = 0.0F;
  float y = 0.0F;
  float z = 0.0F;
  float intensity = 0.0F;  // 0 when the file has none
};

// Reads x y z and, when present, intensity (or KITTI's reflectance) into `out` (cleared first).
void read_pcd(const std::filesystem::path& file, std::vector<CloudPoint>& out);
void read_kitti_bin(const std::filesystem::path& file, std::vector<CloudPoint>& out);

// Binary PCD with fields x y z intensity range time_offset_ns ring return_index.
void write_pcd(const std::filesystem::path& file, const LidarScan& scan);
// Binary little-endian PLY with the same fields.
void write_ply(const std::filesystem::path& file, const LidarScan& scan);

}  // namespace adit::drivers
