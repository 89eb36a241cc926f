#pragma once
// As-built against as-designed: each map point's signed distance to the
// prior's surface, and the regions that deviate by more than a threshold.
//
// The distance is to the nearest piece of the prior's surface: over the prior
// points within reach, the smallest of the distance to a point's plane (its
// normal) where the map point lies over that point's patch (its foot on the
// plane within `patch_spacings` of the prior's point spacing), and the
// distance to a point itself (where no patch covers the map point, or the
// point has no normal: an edge, clutter). A prior sampled every 10 cm is up to
// 7 cm away point-to-point from a point lying on its surface, so the planes
// carry the measure; taking the nearest patch, not the nearest point's plane,
// keeps a point near a corner on its own surface (the corner's samples have
// no normal, or one fitted across both faces), as CloudCompare's cloud-to-cloud
// distance with local models does. Its sign faces the observer: positive in front of the designed
// surface (something built into the designed space: furniture, a wall moved
// in), negative behind it (a wall moved out, a missing column's place). A
// point with no prior surface within `max_distance_m` stands in the designed
// free space: +max_distance_m. Regions: the voxels where at least
// `region_min_share` of the map points deviate, grouped by 26-connection (a
// flood fill), the small ones left out as noise.

#include <span>
#include <vector>

#include <Eigen/Core>

#include "adit/slam/prior_map.hpp"

namespace adit::slam {

struct DeviationConfig {
  float threshold_m = 0.05F;       // |deviation| above this: deviating
  float max_distance_m = 0.5F;     // beyond: the designed free space
  float patch_spacings = 1.5F;     // a prior point's plane covers what lies within this many point spacings of it
  float region_voxel_m = 0.2F;     // connectivity of a region
  float region_min_share = 0.25F;  // a voxel joins a region when this share of its points deviates
  std::size_t min_region_points = 50;
  float viewpoint_voxel_m = 5.0F;  // viewpoints are looked up within 1.5 of these voxels (farther: the sign stays +)
};

// `points` and `viewpoints` (sensor positions along the trajectory) in the
// prior's frame.
std::vector<float> signed_deviations(std::span<const Eigen::Vector3f> points,
                                     std::span<const Eigen::Vector3f> viewpoints, const PriorMap& prior,
                                     const DeviationConfig& config = {});

// Each deviation replaced by the mean over the points of its voxel (edge
// `voxel_m`): a map's range noise (2 cm σ) averaged over the dozen points of a
// 10 cm voxel, so a threshold of 5 cm is crossed by real differences, not by noise.
std::vector<float> smooth_deviations(std::span<const Eigen::Vector3f> points, std::span<const float> deviations,
                                     float voxel_m);

struct DeviationRegion {
  std::size_t points = 0;
  Eigen::Vector3f lo = Eigen::Vector3f::Zero();   // bounding box
  Eigen::Vector3f hi = Eigen::Vector3f::Zero();
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  float mean_m = 0.0F;                            // mean signed deviation
  float max_abs_m = 0.0F;
};

// Regions of points with |deviation| > threshold_m, in voxels where enough of
// the points deviate (DeviationConfig), largest first; `member`
// (if not empty, points.size() long) gets each point's region index, or -1.
std::vector<DeviationRegion> deviation_regions(std::span<const Eigen::Vector3f> points,
                                               std::span<const float> deviations, const DeviationConfig& config,
                                               std::span<int> member = {});

}  // namespace adit::slam
