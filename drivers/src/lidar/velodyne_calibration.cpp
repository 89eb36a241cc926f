// The Velodyne calibration YAML, as written by the ROS velodyne driver's
// gen_calibration tool and shipped by Velodyne per unit: a `lasers:` list of
// maps (laser_id, rot_correction, vert_correction, dist_correction, ... ;
// angles in radians, lengths in metres), `num_lasers`, `distance_resolution`.

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/velodyne.hpp"

namespace adit::drivers {
namespace {

std::string where(const std::string& source, const YAML::Mark& mark) {
  if (mark.line < 0) return source;
  return source + ":" + std::to_string(mark.line + 1);
}

double read_number(const YAML::Node& map, const char* key, const std::string& source, bool required,
                   const std::string& prefix) {
  const YAML::Node node = map[key];
  if (!node) {
    if (required) throw InputError(where(source, map.Mark()), prefix + key, "missing");
    return 0.0;
  }
  double value = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value)) {
    throw InputError(where(source, node.Mark()), prefix + key, "not a finite number");
  }
  return value;
}

}  // namespace

VelodyneCalibration parse_velodyne_calibration(std::string_view yaml, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml));
  } catch (const YAML::Exception& e) {
    throw InputError(where(source, e.mark), "", "not valid YAML: " + e.msg);
  }
  if (!root.IsMap()) throw InputError(source, "", "not a Velodyne calibration (want a map with `lasers:`)");
  const YAML::Node lasers = root["lasers"];
  if (!lasers || !lasers.IsSequence() || lasers.size() == 0) {
    throw InputError(where(source, root.Mark()), "lasers", "missing or not a non-empty list");
  }
  if (lasers.size() > 256) throw InputError(where(source, lasers.Mark()), "lasers", "more than 256 lasers");

  VelodyneCalibration out;
  out.source = source;
  out.lasers.resize(lasers.size());
  std::vector<bool> seen(lasers.size(), false);
  for (std::size_t i = 0; i < lasers.size(); ++i) {
    const YAML::Node laser = lasers[i];
    const std::string prefix = "lasers[" + std::to_string(i) + "].";
    if (!laser.IsMap()) throw InputError(where(source, laser.Mark()), "lasers[" + std::to_string(i) + "]", "not a map");
    const double id = read_number(laser, "laser_id", source, true, prefix);
    if (id < 0 || id >= static_cast<double>(lasers.size()) || id != std::floor(id)) {
      throw InputError(where(source, laser["laser_id"].Mark()), prefix + "laser_id",
                       "must be an integer in [0, " + std::to_string(lasers.size()) + ")");
    }
    const auto index = static_cast<std::size_t>(id);
    if (seen[index]) {
      throw InputError(where(source, laser["laser_id"].Mark()), prefix + "laser_id",
                       "laser " + std::to_string(index) + " appears twice");
    }
    seen[index] = true;
    VelodyneLaser& l = out.lasers[index];
    l.laser_id = static_cast<int>(index);
    l.rot_correction = read_number(laser, "rot_correction", source, true, prefix);
    l.vert_correction = read_number(laser, "vert_correction", source, true, prefix);
    l.dist_correction = read_number(laser, "dist_correction", source, false, prefix);
    l.dist_correction_x = read_number(laser, "dist_correction_x", source, false, prefix);
    l.dist_correction_y = read_number(laser, "dist_correction_y", source, false, prefix);
    l.vert_offset_correction = read_number(laser, "vert_offset_correction", source, false, prefix);
    l.horiz_offset_correction = read_number(laser, "horiz_offset_correction", source, false, prefix);
    l.focal_distance = read_number(laser, "focal_distance", source, false, prefix);
    l.focal_slope = read_number(laser, "focal_slope", source, false, prefix);
    constexpr double kHalfPi = std::numbers::pi / 2;
    if (std::abs(l.vert_correction) >= kHalfPi || std::abs(l.rot_correction) > std::numbers::pi) {
      throw InputError(where(source, laser.Mark()), prefix + "vert_correction",
                       "angles must be radians within ±π/2 (vertical) and ±π (rotational)");
    }
    if (std::abs(l.dist_correction) > 10.0 || std::abs(l.vert_offset_correction) > 1.0 ||
        std::abs(l.horiz_offset_correction) > 1.0) {
      throw InputError(where(source, laser.Mark()), prefix + "dist_correction",
                       "corrections must be metres (|distance| ≤ 10, |offsets| ≤ 1)");
    }
  }
  if (root["num_lasers"]) {
    const double n = read_number(root, "num_lasers", source, true, "");
    if (n != static_cast<double>(lasers.size())) {
      throw InputError(where(source, root["num_lasers"].Mark()), "num_lasers",
                       "says " + std::to_string(static_cast<long long>(n)) + " but `lasers:` lists " +
                           std::to_string(lasers.size()));
    }
  }
  if (root["distance_resolution"]) {
    out.distance_resolution_m = read_number(root, "distance_resolution", source, true, "");
    if (out.distance_resolution_m <= 0.0 || out.distance_resolution_m > 0.1) {
      throw InputError(where(source, root["distance_resolution"].Mark()), "distance_resolution",
                       "must be metres in (0, 0.1]");
    }
  }
  return out;
}

VelodyneCalibration load_velodyne_calibration(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot read the calibration file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_velodyne_calibration(text.str(), file.string());
}

}  // namespace adit::drivers
