#include <array>
#include <numbers>
#include <sstream>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/velodyne_encoder.hpp"

namespace adit::drivers {
namespace {

// VLP-16 User Manual rev. E, table 9-1: vertical angle (°) and vertical correction (mm) by laser id.
constexpr std::array<double, 16> kVlp16AngleDeg{-15, 1, -13, 3, -11, 5, -9, 7, -7, 9, -5, 11, -3, 13, -1, 15};
constexpr std::array<double, 16> kVlp16OffsetMm{11.2, -0.7, 9.7, -2.2, 8.1, -3.7, 6.6, -5.1,
                                                 5.1,  -6.6, 3.7, -8.1, 2.2, -9.7, 0.7, -11.2};

}  // namespace

VelodyneCalibration velodyne_nominal_calibration(VelodyneModel model) {
  if (model != VelodyneModel::vlp16) {
    throw InputError("", "model", "no nominal calibration tabulated for the " + std::string(to_string(model)));
  }
  VelodyneCalibration c;
  c.source = "VLP-16 nominal (manual table 9-1)";
  c.distance_resolution_m = velodyne_distance_resolution_m(model);
  for (std::size_t i = 0; i < kVlp16AngleDeg.size(); ++i) {
    VelodyneLaser l;
    l.laser_id = static_cast<int>(i);
    l.vert_correction = kVlp16AngleDeg[i] * std::numbers::pi / 180.0;
    l.vert_offset_correction = kVlp16OffsetMm[i] / 1000.0;
    c.lasers.push_back(l);
  }
  return c;
}

std::string format_velodyne_calibration(const VelodyneCalibration& calibration) {
  std::ostringstream out;
  out.precision(17);
  out << "# Velodyne calibration (" << calibration.source << ")\n";
  if (calibration.distance_resolution_m > 0) out << "distance_resolution: " << calibration.distance_resolution_m << "\n";
  out << "num_lasers: " << calibration.lasers.size() << "\nlasers:\n";
  for (const VelodyneLaser& l : calibration.lasers) {
    out << "- {laser_id: " << l.laser_id << ", rot_correction: " << l.rot_correction
        << ", vert_correction: " << l.vert_correction << ", dist_correction: " << l.dist_correction
        << ", dist_correction_x: " << l.dist_correction_x << ", dist_correction_y: " << l.dist_correction_y
        << ", vert_offset_correction: " << l.vert_offset_correction
        << ", horiz_offset_correction: " << l.horiz_offset_correction << ", focal_distance: " << l.focal_distance
        << ", focal_slope: " << l.focal_slope << "}\n";
  }
  return out.str();
}

}  // namespace adit::drivers
