#pragma once
// The true width and height of a drift at a cross-section: the scene mesh cut
// by the vertical plane through `centre` square to `along` (world frame); the
// floor and roof are the cut's nearest crossings of the vertical through the
// centre, below and above it; the width is measured at width_at_m above that
// floor between the cut's nearest crossings each side. The same definitions
// as products/cross_sections.hpp, on the exact surfaces.

#include <span>

#include <Eigen/Core>

#include "adit/eval/mesh_distance.hpp"

namespace adit::eval {

struct SectionTruth {
  double floor_z = 0.0, roof_z = 0.0;
  double width_m = 0.0, height_m = 0.0;  // NaN when the cut has no wall, floor or roof there
};

SectionTruth section_truth(std::span<const Triangle> scene, const Eigen::Vector3d& centre, const Eigen::Vector3d& along,
                           double width_at_m);

}  // namespace adit::eval
