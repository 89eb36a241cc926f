#pragma once
// Geometric verification of a loop candidate: the query keyframe's scan is
// registered (slam/registration.hpp, the odometry's own point-to-plane
// Gauss-Newton, no prior) against a submap of the keyframes around the
// candidate, placed in the candidate's frame by the graph. The loop is
// accepted only when the registration
//   - overlaps: inlier_ratio ≥ min_inlier_ratio (the share of the scan with a
//     plane of the submap within reach; a person in front of the sensor or a
//     different drift lowers it),
//   - fits: the robust RMS of the point-to-plane residuals ≤ max_rmse_m,
//   - is conditioned: the data Hessian's weakest normalised eigenvalue
//     ≥ min_conditioning (Zhang, Kaess & Singh, ICRA 2016). Along a plain
//     tunnel the translation along the axis is unobserved, so a registration
//     "fits" anywhere along it. Such a loop is accepted as *partial*: its
//     information along the weakest direction is removed, so it holds the
//     directions the scan does observe (across the tunnel, height, attitude)
//     and says nothing along the axis, where the registration's step was
//     projected off and the measurement is the graph's own guess anyway
//     (solution remapping). With allow_partial false it is refused;
//   - is unambiguous: registered from every initial guess (the graph's
//     relative pose and Scan Context's two yaw readings), no two guesses
//     converge to different poses that both pass (a symmetric or repetitive
//     section matches two ways; neither is trusted). With heading_gate_rad,
//     a passing pose turned farther than that from the first guess (the
//     graph's) is not a reading the graph allows and is set aside before
//     this check: a tunnel symmetric under a half turn, driven back the
//     other way, matches at 0° and 180°, and the graph's heading, good to a
//     few degrees, says which.
// The accepted measurement's information is fixed σ (covariance_sigma_*),
// not the registration's covariance: that one is scaled by the odometry's
// deliberately loose point σ (decision 010) and optimistic in its shape
// (Censi, ICRA 2007); the acceptance thresholds above bound the fit instead.

#include <span>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "adit/slam/lie.hpp"
#include "adit/slam/registration.hpp"
#include "adit/slam/voxel_hash_map.hpp"

namespace adit::slam {

struct LoopVerificationConfig {
  float submap_voxel_m = 0.5F;          // as the refinement map (slam/map_refiner.hpp)
  float submap_point_spacing_m = 0.1F;
  std::size_t submap_capacity_voxels = std::size_t{1} << 16;
  double max_distance_m = 1.5;          // correspondences: the guess may be the drift plus a yaw sector off
  double kernel_scale_m = 0.5;
  double min_inlier_ratio = 0.6;
  double max_rmse_m = 0.08;
  double min_conditioning = 0.02;       // twice the odometry's degeneracy threshold (RegistrationConfig)
  double ambiguity_m = 0.5;             // two passing solutions this far apart: ambiguous
  double ambiguity_rad = 0.1;
  // > 0: passing poses whose rotation differs from guesses[0]'s by more are
  // set aside (LoopVerification::set_aside) when one within it passes.
  double heading_gate_rad = 0.0;
  double covariance_sigma_m = 0.05;     // σ of an accepted loop's translation, per axis
  double covariance_sigma_rad = 0.005;  // and rotation
  bool allow_partial = true;            // an ill-conditioned fit becomes a partial loop (above)
  RegistrationConfig registration;
};

enum class LoopVerdict { accepted, partial, no_overlap, poor_fit, ill_conditioned, ambiguous };
std::string_view to_string(LoopVerdict verdict);

struct LoopVerification {
  LoopVerdict verdict = LoopVerdict::no_overlap;
  Eigen::Isometry3d relative = Eigen::Isometry3d::Identity();  // T_candidate⁻¹·T_query, measured
  // Of the pose graph's loop residual (slam/src/pose_graph_factors.hpp):
  // [translation in the candidate's frame; rotation in the query's].
  Matrix6d information = Matrix6d::Identity();
  Eigen::Vector3d free_axis = Eigen::Vector3d::Zero();  // partial: the unobserved translation, candidate frame (unit)
  RegistrationResult registration;                             // the best guess's
  int passing_guesses = 0;
  int set_aside = 0;  // passing poses outside the heading gate
};

// Adds `points` (a keyframe's scan, its body frame) placed at `pose` into `submap`.
void add_to_submap(VoxelHashMap& submap, std::span<const Eigen::Vector3f> points, const Eigen::Isometry3d& pose);

// `query_points`: the query keyframe's scan (its body frame); `submap`: the
// candidate's surroundings in the candidate's frame; `guesses`: initial
// T_candidate⁻¹·T_query.
LoopVerification verify_loop(std::span<const Eigen::Vector3f> query_points, const VoxelHashMap& submap,
                             std::span<const Eigen::Isometry3d> guesses, const LoopVerificationConfig& config = {});

}  // namespace adit::slam
