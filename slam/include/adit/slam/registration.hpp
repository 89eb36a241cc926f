#pragma once
// Scan-to-map registration: robust Gauss-Newton on SE(3) minimising
// point-to-plane distances (Chen & Medioni 1992) to local planes of the map,
// each fitted through the map points nearest the query (as LOAM, Zhang &
// Singh 2014, and FAST-LIO2, Xu et al. 2022), with a graduated Geman-McClure
// kernel (Black & Rangarajan 1996; the scale schedule in the spirit of GNC,
// Yang et al. 2020) and an optional Gaussian prior on the pose (wheel
// odometry or constant velocity).
//
// The update is a body-frame perturbation, T ← T·exp(δ): the Hessian's
// translation and rotation blocks then mean the same wherever the sensor is
// (in a world-frame perturbation a rotation about the world origin 100 m
// away is mostly translation), and so do the prior and the degeneracy test.
//
// Degeneracy (Zhang, Kaess & Singh, ICRA 2016): the data term's Hessian is
// split into its translation and rotation blocks, each normalised per unit
// weight so the threshold means the same for any number of points (rotation
// eigenvalues then read as squared lever arm in m²).
// Eigen-directions below `degeneracy_threshold` are the ones the scan cannot
// constrain; there the update is projected out ("solution remapping"), so the
// pose keeps the prior's estimate, and the result reports the weakest one.

#include <cstdint>
#include <span>

#include <Eigen/Geometry>

#include "adit/slam/lie.hpp"
#include "adit/slam/voxel_hash_map.hpp"

namespace adit::slam {

struct RegistrationConfig {
  int max_iterations = 30;
  double convergence_norm = 5e-4;       // settle when the update is below this (m, rad)
  double min_kernel_scale_m = 0.05;     // the robust kernel's final scale (about 2-3 σ of range noise)
  // The robust kernel's scale halves only after an iteration whose update
  // (m, rad) is below this: narrowed while the pose is still far off, the
  // kernel weighs the residuals that would pull it in to nothing and the
  // prior holds it there (decision 042).
  double narrow_below_step = 0.01;
  float max_plane_error_m = 0.1F;       // a map neighbour farther than this from its plane: not a plane
  // Planes are searched again once the pose moved this far since the last
  // search (with a `planes` buffer; without one, every iteration).
  double reassociate_m = 0.02;
  double reassociate_rad = 0.002;
  int plane_neighbors = 10;             // map points a plane is fitted through (5: planes too noisy to see a drift's axis as degenerate)
  // Effective σ of one point-to-plane residual: the scan's information is
  // Σ w·JᵀJ / σ², in the same units as the prior's. Far above the range noise
  // because residuals are not independent (shared map points, the rings'
  // sampling pattern, which biases a self-similar drift towards "no motion").
  // A small σ lets that biased scan overrule the wheels along a drift;
  // constrained directions still follow the scan at 1 m
  // (docs/decisions/010-scan-weight.md).
  double point_sigma_m = 1.0;
  // Normalised eigenvalue below which a direction is degenerate: 0.01 means
  // fewer than ~1% of the residuals watch it. With 10-point planes it flags a
  // smooth drift's axis and leaves a rough mine mostly observed, where the
  // remapping keeps the wheels' estimate
  // (docs/decisions/009-planes-from-nearest-points.md).
  double degeneracy_threshold = 0.01;
  int min_plane_correspondences = 100;  // fewer: every direction counts as degenerate
};

// A Gaussian prior on the pose: mean and information (inverse covariance) in
// the body-frame tangent space at the mean, twist order [v; ω]: the pose is
// mean·exp(ε), ε ~ N(0, information⁻¹).
// Gravity's direction as an accelerometer measures it (the kinematic
// acceleration removed): `up_body`, a unit vector in the body frame, should
// be `up_frame` once rotated into the map frame, R·up_body = up_frame. The
// residual R·up_body − up_frame constrains roll and pitch only (yaw turns
// about the vertical). Unlike a prior on the pose, it does not follow the
// map: a tilt the odometry took into its own map cannot drag it along.
struct GravityPrior {
  Eigen::Vector3d up_body = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d up_frame = Eigen::Vector3d::UnitZ();
  double information = 0.0;  // 1/σ², σ the tilt error in rad; 0 = no gravity
};

struct PosePrior {
  Eigen::Isometry3d mean = Eigen::Isometry3d::Identity();
  Matrix6d information = Matrix6d::Zero();
  GravityPrior gravity;
};

// Continuous-time registration (in the spirit of CT-ICP, Dellenbach et al.
// 2022): a spinning sensor measures each point at its own time, so a scan
// holds the sweep's motion as well as its pose. With `times_s`, `points` are
// taken as measured (not deskewed), each is moved to the scan start by the
// body velocity ξ over the sweep, T(t) = exp(t·ξ), and ξ is estimated with the
// pose under a Gaussian prior. A bump that pitches the body at 30°/s turns it
// 3° in one 0.1 s sweep: deskewed with the wheels' planar motion, such a scan
// registers 1–2 sweeps' worth of rotation off at range.
// Jacobian: T·exp(t(ξ+δξ))·p ≈ T·exp(tξ)·(p + t(δv + δω×p)) for small tξ, so
// ∂r/∂δξ = t·∂r/∂δ (the pose's body-frame Jacobian scaled by the point's time).
struct SweepMotion {
  std::span<const float> times_s;          // per point, after the scan start; empty: points are deskewed
  Vector6d velocity = Vector6d::Zero();    // the prior's mean and first guess: body twist per second [v; ω]
  Matrix6d information = Matrix6d::Zero(); // of the velocity prior, per (m/s)² and (rad/s)²
  bool estimate = false;                   // false: deskew with `velocity` as given
  std::span<Eigen::Vector3f> deskewed;     // scratch of points.size(): the points deskewed with the final velocity
};

// A prior map (a BIM model, an earlier survey: prior_map.hpp) the scan is
// registered against together with the local map: each point's plane in the
// prior adds a point-to-plane residual to the same robust least squares, as
// the BIM-aided odometry that issue #22 describes registers against the
// model beside its own map. Where the prior agrees, both pull alike; where
// it lacks what was built (furniture, new supports) the point finds no
// prior plane within the threshold, or a far one the kernel weighs down;
// where the prior is missing the local map carries the scan alone. The
// local map then holds scans placed in the prior's frame, so drift stays
// bounded by the prior's accuracy instead of growing with the path.
// Residual r = n·(A·T·p − m) with A = prior_from_frame fixed; for T·exp(δ),
// ∂r/∂[v; ω] = [n_b; p × n_b] with n_b = (A_R·R)ᵀ·n, as for the local map.
struct PriorMapTerm {
  const VoxelHashMap* index = nullptr;  // the prior's index (index_prior_map); null: no prior (not owned)
  Eigen::Isometry3d prior_from_frame = Eigen::Isometry3d::Identity();  // the registration's frame in the prior's
  double weight = 1.0;                  // of a prior residual, against a local-map one's 1
  std::span<MapPlane> planes;           // per point, as `planes`: the prior planes kept between iterations
  int stride = 1;                       // every stride-th point looks up the prior (its cost halves at 2)
};

struct RegistrationResult {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  // Of the pose, [v; ω], for a world-frame (left) perturbation exp(ε)·pose.
  Matrix6d covariance = Matrix6d::Identity();
  int iterations = 0;
  int correspondences = 0;      // points with a map neighbour within the threshold
  int prior_correspondences = 0;  // points with a plane of the prior map within it (PriorMapTerm)
  double inlier_ratio = 0.0;    // correspondences / points
  double rmse_m = 0.0;          // robust-weighted RMS of the residuals: sqrt(Σw·r² / Σw)
  bool degenerate = false;
  Vector6d weakest_direction = Vector6d::Zero();  // unit twist (body frame) of the least constrained direction
  double weakest_eigenvalue = 0.0;                // its normalised eigenvalue (the smaller is weaker)
  Vector6d sweep_velocity = Vector6d::Zero();     // body twist per second over the sweep (the SweepMotion's when not estimated)
};

// `points` are in the body frame at the scan time (deskewed); `prior.mean`
// also serves as the initial guess. `max_distance_m` bounds correspondences;
// `kernel_scale_m` is the robust kernel's starting scale (the adaptive
// threshold's σ/3, as in KISS-ICP), narrowed to config.min_kernel_scale_m.
RegistrationResult register_scan(std::span<const Eigen::Vector3f> points, const VoxelHashMap& map,
                                 const PosePrior& prior, double max_distance_m, double kernel_scale_m,
                                 const RegistrationConfig& config = {});
// The same, keeping each point's plane in `planes` (at least points.size()
// long) between iterations, so that steady-state calls allocate nothing.
RegistrationResult register_scan(std::span<const Eigen::Vector3f> points, const VoxelHashMap& map,
                                 const PosePrior& prior, double max_distance_m, double kernel_scale_m,
                                 const RegistrationConfig& config, std::span<MapPlane> planes);
// The same on a scan as measured, deskewed (and its sweep velocity estimated) as `sweep` says.
RegistrationResult register_scan(std::span<const Eigen::Vector3f> points, const VoxelHashMap& map,
                                 const PosePrior& prior, double max_distance_m, double kernel_scale_m,
                                 const RegistrationConfig& config, std::span<MapPlane> planes,
                                 const SweepMotion& sweep);
// The same, registered against a prior map as well.
RegistrationResult register_scan(std::span<const Eigen::Vector3f> points, const VoxelHashMap& map,
                                 const PosePrior& prior, double max_distance_m, double kernel_scale_m,
                                 const RegistrationConfig& config, std::span<MapPlane> planes,
                                 const SweepMotion& sweep, const PriorMapTerm& prior_map);

}  // namespace adit::slam
