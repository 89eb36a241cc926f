#pragma once
// Cross-sections of the map across the path at set intervals, as mine
// surveyors take them to watch convergence: at each station (every
// interval_m of path length), the map points within slab_m of the vertical
// plane square to the path, in (u across, z up); the floor and the roof
// over the path (medians of the points below and above the sensor within
// 0.75 m of it), the height between them, and the width at
// width_at_m above the floor (the innermost wall points on each side within
// ±band_m of that height, their median). Written as SVG with the
// dimensions on them, and as one CSV row each.
//
// A surveyor sets a convergence station where the drift runs on, not across
// a door, a junction or a niche: there the width is not the drift's (the
// innermost point is a jamb or the far wall of a side drift). So a station is
// moved along the path, nearest first in steps of shift_step_m up to
// max_shift_m, to where both walls at the width's height lie within
// wall_tolerance_m of their place at the station in the sections
// regular_span_m before and after it; with no such place within reach the
// station keeps its nominal place and its width is not given (NaN).

#include <filesystem>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "adit/slam/trajectory.hpp"

namespace adit::products {

struct SectionOptions {
  double interval_m = 10.0;
  double slab_m = 0.05;        // half-thickness of the slab of points
  double width_at_m = 1.5;     // the width is measured this high above the floor
  double band_m = 0.10;        // ± around that height
  double max_half_width_m = 15.0;
  double max_shift_m = 2.0;        // 0: every station at its nominal chainage, walls not checked
  double shift_step_m = 0.5;
  double regular_span_m = 0.5;     // the walls are compared this far before and after the station
  double wall_tolerance_m = 0.25;  // more than the roughness of a drilled and blasted wall, less than a door's depth
};

struct CrossSection {
  int id = 0;
  double chainage_m = 0.0;         // path length to the station
  double shift_m = 0.0;            // from the nominal chainage (a multiple of interval_m) to where the walls run on
  bool walls_regular = true;       // false: no place within max_shift_m where they do (width NaN)
  Eigen::Vector3d centre{0, 0, 0};  // the sensor at the station (map frame)
  Eigen::Vector2d across{0, 1};     // unit, horizontal, to the left of the path
  double floor_z = 0.0, roof_z = 0.0;
  double left_u = 0.0, right_u = 0.0;  // walls, along `across` (left > 0)
  double width_m = 0.0, height_m = 0.0;  // NaN when not measured (no wall, floor or roof)
  std::vector<Eigen::Vector2f> profile;  // (u, z) of the slab's points
};

std::vector<CrossSection> cut_sections(std::span<const Eigen::Vector3f> points, const slam::Trajectory& sensor_path,
                                       const SectionOptions& options);

// SVG of one section with its width and height dimensions; returns bytes written.
std::uintmax_t write_section_svg(const std::filesystem::path& file, const CrossSection& s, const SectionOptions& o);
// id,chainage_m,x,y,z,across_x,across_y,floor_z,roof_z,width_m,height_m
void write_sections_csv(const std::filesystem::path& file, std::span<const CrossSection> sections);

}  // namespace adit::products
