#pragma once
// The top-down picture of a session's map (PNG): each pixel coloured by the
// height above the ground of the highest map point over it below the roof
// band (viridis, 0 at the floor to band_high_m), the path drawn in red from a
// green start, targets as magenta discs, a scale bar and the colour scale.

#include <cstdint>
#include <filesystem>
#include <span>

#include <Eigen/Core>

#include "adit/products/ground.hpp"
#include "adit/slam/trajectory.hpp"

namespace adit::products {

struct TopViewOptions {
  double pixel_m = 0.05;
  int max_side_px = 4000;     // larger maps get larger pixels
  double band_high_m = 2.0;   // points higher above the ground (the roof) are not drawn
};

struct TopViewReport {
  int width = 0, height = 0;
  double pixel_m = 0.0;
  double scale_bar_m = 0.0;
  std::uintmax_t bytes = 0;
};

TopViewReport write_top_view(const std::filesystem::path& file, std::span<const Eigen::Vector3f> points,
                             const GroundModel& ground, const slam::Trajectory& path,
                             std::span<const Eigen::Vector3d> targets, const TopViewOptions& options);

// 1, 2 or 5 times a power of ten, the largest not above `at_most`.
double nice_length(double at_most);

}  // namespace adit::products
