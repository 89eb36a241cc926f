#pragma once
// The decoded LiDAR point and scan, shared by every sensor family.
//
// Points are in the sensor frame, metres, x forward, y left, z up (REP-103),
// after the family's calibration. `time_offset_ns` is the firing time of the
// point minus the scan's start time, taken from the sensor's own firing
// timing, which is what deskewing needs.

#include <cstdint>
#include <vector>

namespace adit::drivers {

struct LidarPoint {
  float x = 0.0F;
  float y = 0.0F;
  float z = 0.0F;
  float intensity = 0.0F;        // the sensor's reflectivity / intensity value
  float range_m = 0.0F;          // measured range after calibration
  std::uint32_t time_offset_ns = 0;
  std::uint16_t ring = 0;        // beam index, 0 = the lowest elevation
  std::uint8_t return_index = 0; // 0 first/strongest, 1 second/last (dual modes)
  std::uint8_t reserved = 0;
  // Raw per-pixel values of formats that have them (Ouster), 0 otherwise:
  // with intensity (reflectivity) and range_m they keep a sensor's raw fields
  // through scan assembly. Two u16 round the point to 32 bytes.
  std::uint16_t signal = 0;      // Ouster signal photons
  std::uint16_t near_ir = 0;     // Ouster near-infrared (ambient) photons
};

struct ScanStats {
  std::uint32_t packets = 0;
  std::uint32_t missing_packets = 0;
  std::uint32_t duplicate_packets = 0;
  std::uint32_t out_of_order_packets = 0;
  bool complete = false;  // a full revolution with no packet missing
};

struct LidarScan {
  std::int64_t start_time_ns = 0;         // host clock (CLOCK_REALTIME ns) of the first firing
  std::int64_t sensor_start_time_ns = 0;  // the same instant on the sensor's own clock
  std::vector<LidarPoint> points;
  ScanStats stats;

  // Reuses the storage: the live path keeps one scan per slot and never frees.
  void clear() {
    points.clear();
    stats = {};
    start_time_ns = 0;
    sensor_start_time_ns = 0;
  }
};

}  // namespace adit::drivers
