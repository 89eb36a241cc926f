#pragma once
// Global localisation against a prior map from an unknown start: where, in
// the prior's frame, is a cloud of a few accumulated scans?
//
// 1. Plan-view correlative search (Olson, ICRA 2009; Hess et al., ICRA 2016):
//    the cloud's vertical-surface points, levelled by gravity, are scored
//    against the prior's plan likelihood field at every free floor cell and
//    every yaw step, by branch and bound over blocks of cells (plan_search.hpp:
//    the exhaustive search's peaks, the global optimum and its rivals, for a
//    fraction of its sums). The best few distinct peaks are hypotheses.
// 2. Each hypothesis is refined in 3-D by the odometry's own registration
//    (register_scan: point-to-plane, Geman-McClure kernel) against the prior.
// 3. Checks, so that a wrong pose is never reported as found: the overlap
//    (share of the cloud's wall points on the prior after refinement), the
//    ambiguity (the best distinct rival's overlap against the best's, as the
//    ratio test of Lowe 2004 / the second-best check of place recognition),
//    the registration's conditioning (Zhang, Kaess & Singh 2016) and its
//    covariance.
// docs/PRIOR-MAP.md; choices and their evidence: docs/decisions/026-prior-map-correlative-search.md.

#include <optional>
#include <span>
#include <string>

#include <Eigen/Geometry>

#include "adit/slam/lie.hpp"
#include "adit/slam/prior_map.hpp"
#include "adit/slam/voxel_hash_map.hpp"

namespace adit::slam {

// An approximate start (from the tablet): narrows the search to a disc and a yaw range.
struct LocalisationHint {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // prior frame, m
  double radius_m = 5.0;
  double yaw_rad = 0.0;
  double yaw_tolerance_rad = 0.35;  // ± round yaw_rad; π or more: any heading
};

struct LocalisationConfig {
  double yaw_step_rad = 0.025;           // 1.4°: a wall 10 m away moves 0.25 m (one plan cell)
  float cloud_voxel_m = 0.2F;            // downsampling of the cloud before its normals
  float search_range_m = 30.0F;          // cloud points beyond this horizontal range are left out of the search
  std::size_t max_search_points = 600;   // plan points correlated (spread evenly over the cloud's wall points)
  float min_wall_clearance_m = 0.3F;     // a start cell this close to a wall is not a place a sensor can be
  int search_levels = 4;                 // the plan search's blocks: 2^4 x 2^4 cells at the top; 0: every cell scored
  int hypotheses = 8;                    // distinct peaks refined in 3-D
  double distinct_m = 1.0;               // peaks closer than this (and distinct_rad) are one
  double distinct_rad = 0.15;
  // Checks (docs/decisions/026-prior-map-correlative-search.md).
  double min_overlap = 0.9;              // share of wall points within overlap_m of the prior after refinement
  double overlap_m = 0.15;               // the prior index is thinned to 1/4 of its 0.5 m voxel: a point on a surface is within 0.09 m of one
  // The best distinct rival must leave at least this many times the best's
  // unexplained wall points (1 − overlap): most of a cloud is long walls that
  // fit anywhere along them, so the overlaps themselves differ little.
  double min_rival_miss_ratio = 1.5;
  double rival_m = 0.3;                  // refined poses this far apart (or rival_rad) are rivals, not one answer
  double rival_rad = 0.035;
  // The refinement's weakest normalised Hessian eigenvalue (RegistrationResult)
  // must clear the odometry's degeneracy threshold (0.01) by this much.
  double min_weakest_eigenvalue = 0.03;
  double point_sigma_m = 0.05;           // σ of one residual for the reported covariance (range noise, planes)
  double max_position_sigma_m = 0.05;    // the refinement's covariance must be at least this tight
  double max_yaw_sigma_rad = 0.0035;
  int min_wall_points = 150;             // fewer: too little seen to tell places apart
};

struct LocalisationResult {
  bool success = false;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // the cloud's frame in the prior's (best hypothesis, even on failure)
  Matrix6d covariance = Matrix6d::Identity();              // of the pose, [v; ω], world-frame perturbation
  std::string failure;                                     // why not, when !success
  double overlap = 0.0;                                    // of the best hypothesis
  double rival_overlap = 0.0;                              // of the best distinct rival (0 when none)
  double rival_distance_m = 0.0;                           // how far that rival lies from the best
  double weakest_eigenvalue = 0.0;                         // of the refinement (RegistrationResult)
  double position_sigma_m = 0.0;                           // largest, from the covariance
  double yaw_sigma_rad = 0.0;
  int hypotheses_refined = 0;
  std::size_t wall_points = 0;                             // of the cloud, used by the search and the checks
};

// The levelled frame localise() wants for a cloud gathered in another frame
// (the odometry's): z along gravity's `up` (a unit vector in that frame), the
// shortest turn from the frame's own z, so the heading is kept as nearly as it
// can be; the origin at `origin` (the sensor: the floor must lie below it).
// Returns level_from_frame.
Eigen::Isometry3d levelled_frame_at(const Eigen::Vector3d& up, const Eigen::Vector3d& origin);

// `cloud`: points in a local frame whose z is up (levelled with gravity; roll
// and pitch are refined, within a few degrees), e.g. a few scans accumulated
// by the odometry. `index`: index_prior_map(prior).
LocalisationResult localise(std::span<const Eigen::Vector3f> cloud, const PriorMap& prior, const VoxelHashMap& index,
                            const std::optional<LocalisationHint>& hint = std::nullopt,
                            const LocalisationConfig& config = {});

}  // namespace adit::slam
