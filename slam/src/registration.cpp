#include "adit/slam/registration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "adit/slam/deskew.hpp"
#include "adit/slam/lie.hpp"

namespace adit::slam {
namespace {

// Geman-McClure IRLS weight, normalised to 1 at zero residual:
// ρ(r) = r²/(κ² + r²)  ⇒  w(r) = ρ'(r)/r ∝ κ⁴/(κ² + r²)².
double geman_mcclure_weight(double r2, double kappa2) {
  const double d = kappa2 + r2;
  return kappa2 * kappa2 / (d * d);
}

using Matrix12d = Eigen::Matrix<double, 12, 12>;
using Vector12d = Eigen::Matrix<double, 12, 1>;

struct NormalEquations {
  Matrix6d H = Matrix6d::Zero();  // pose block
  Vector6d g = Vector6d::Zero();
  Matrix12d H12 = Matrix12d::Zero();  // pose and sweep velocity, when estimated
  Vector12d g12 = Vector12d::Zero();
  double weight_sum = 0.0;
  double residual2_sum = 0.0;  // Σ w·r², robust-weighted
  int count = 0;        // points with a local-map plane
  int prior_count = 0;  // points with a prior-map plane
};

// One pass over the points at pose T: each point's plane in the map, its
// point-to-plane residual r = n·(T p − m), and the Jacobian for the body-frame
// perturbation T·exp(δ): T·exp(δ)·p ≈ T(p + v + ω×p), so with n_b = Rᵀn,
// ∂r/∂[v; ω] = [n_b; p × n_b] (p in the body frame: lever arms are ranges).
// With a prior map, the point's plane there too, the same way through the
// fixed prior_from_frame (PriorMapTerm), weighted by its weight.
NormalEquations build(std::span<const Eigen::Vector3f> points, const VoxelHashMap& map, const Eigen::Isometry3d& T,
                      double max_distance_m, double kappa2, const RegistrationConfig& config,
                      std::span<MapPlane> planes, bool associate, std::span<const float> times_s,
                      const PriorMapTerm& prior_map) {
  NormalEquations ne;
  const bool timed = times_s.size() == points.size();
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  const bool cached = planes.size() >= points.size();
  const bool with_prior = prior_map.index != nullptr;
  const bool prior_cached = prior_map.planes.size() >= points.size();
  const std::size_t prior_stride = static_cast<std::size_t>(std::max(1, prior_map.stride));
  const Eigen::Isometry3f A = prior_map.prior_from_frame.cast<float>();
  const Eigen::Matrix3f prior_R = A.linear() * R;
  const Eigen::Vector3f prior_t = A.linear() * t + A.translation();
  // One residual into the normal equations; R_n maps the plane's frame to the body's.
  // Inlined at both calls: the per-point path was one loop body before the
  // prior came, and a call per residual slowed it (measured under ASan).
  const auto add = [&](std::size_t i, const MapPlane& plane, const Eigen::Vector3f& q, const Eigen::Matrix3f& R_n,
                       double scale) __attribute__((always_inline)) {
    const double r = plane.normal.dot(q - plane.point);
    if (std::abs(r) > max_distance_m) return false;
    const Eigen::Vector3d n_b = (R_n.transpose() * plane.normal).cast<double>();
    Vector6d J;
    J << n_b, points[i].cast<double>().cross(n_b);
    const double w = scale * geman_mcclure_weight(r * r, kappa2);
    if (timed) {
      Vector12d J12;
      J12 << J, static_cast<double>(times_s[i]) * J;
      ne.H12.noalias() += w * J12 * J12.transpose();
      ne.g12.noalias() += w * r * J12;
    } else {
      ne.H.noalias() += w * J * J.transpose();
      ne.g.noalias() += w * r * J;
    }
    ne.weight_sum += w;
    ne.residual2_sum += w * r * r;
    return true;
  };
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    const Eigen::Vector3f q = R * p + t;
    MapPlane local;
    MapPlane& plane = cached ? planes[i] : local;
    // Three queries ahead: their slots arrive while this one is searched.
    constexpr std::size_t kPrefetchAhead = 3;
    if (associate || !cached) {
      if (i + kPrefetchAhead < points.size()) map.prefetch_around(R * points[i + kPrefetchAhead] + t);
      plane = map.nearest_plane(q, config.plane_neighbors, config.max_plane_error_m);
    }
    if (plane.found && add(i, plane, q, R, 1.0)) ++ne.count;
    if (!with_prior || i % prior_stride != 0) continue;
    const Eigen::Vector3f q_prior = prior_R * p + prior_t;
    MapPlane prior_local;
    MapPlane& prior_plane = prior_cached ? prior_map.planes[i] : prior_local;
    if (associate || !prior_cached) {
      if (i + kPrefetchAhead * prior_stride < points.size())
        prior_map.index->prefetch_around(prior_R * points[i + kPrefetchAhead * prior_stride] + prior_t);
      prior_plane = prior_map.index->nearest_plane(q_prior, config.plane_neighbors, config.max_plane_error_m);
    }
    if (prior_plane.found && add(i, prior_plane, q_prior, prior_R, prior_map.weight)) ++ne.prior_count;
  }
  if (timed) {
    ne.H = ne.H12.topLeftCorner<6, 6>();
    ne.g = ne.g12.head<6>();
  }
  return ne;
}

struct Degeneracy {
  Eigen::Matrix3d translation_projector = Eigen::Matrix3d::Identity();  // onto constrained directions
  Eigen::Matrix3d rotation_projector = Eigen::Matrix3d::Identity();
  bool degenerate = false;
  Vector6d weakest = Vector6d::Zero();
  double weakest_eigenvalue = 0.0;
};

// Zhang, Kaess & Singh 2016, per block: eigen-directions of the normalised
// data Hessian below the threshold are not constrained by the scan.
Degeneracy analyse(const NormalEquations& ne, double threshold, int min_correspondences) {
  Degeneracy d;
  if (ne.weight_sum <= 0.0) {
    d.degenerate = true;
    d.translation_projector.setZero();
    d.rotation_projector.setZero();
    d.weakest << 1, 0, 0, 0, 0, 0;
    return d;
  }
  d.degenerate = ne.count + ne.prior_count < min_correspondences;
  // Per unit weight: translation eigenvalues are the share of residuals that
  // watch a direction (0..1); rotation ones are that share times the squared
  // lever arm in m², i.e. displacement per radian judged at 1 m.
  const Eigen::Matrix3d Ht = ne.H.topLeftCorner<3, 3>() / ne.weight_sum;
  const Eigen::Matrix3d Hr = ne.H.bottomRightCorner<3, 3>() / ne.weight_sum;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> et;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> er;
  et.computeDirect(Ht);
  er.computeDirect(Hr);
  d.weakest_eigenvalue = std::numeric_limits<double>::max();
  for (int block = 0; block < 2; ++block) {
    const auto& solver = block == 0 ? et : er;
    Eigen::Matrix3d& projector = block == 0 ? d.translation_projector : d.rotation_projector;
    for (int i = 0; i < 3; ++i) {
      const double lambda = solver.eigenvalues()(i);
      const Eigen::Vector3d direction = solver.eigenvectors().col(i);
      if (lambda < d.weakest_eigenvalue) {
        d.weakest_eigenvalue = lambda;
        d.weakest.setZero();
        d.weakest.segment<3>(3 * block) = direction;
      }
      if (lambda < threshold) {
        d.degenerate = true;
        projector -= direction * direction.transpose();
      }
    }
  }
  return d;
}

// The gravity factor's normal equations at rotation R: residual
// r = R·u_b − u_f; with R·exp(δω), R·exp(δω)·u_b ≈ R·(u_b + δω × u_b), so
// ∂r/∂δω = −R·[u_b]×, and JᵀJ = I − u_b·u_bᵀ (no information about yaw).
struct GravityTerms {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
};

GravityTerms gravity_terms(const GravityPrior& gravity, const Eigen::Matrix3d& R) {
  GravityTerms terms;
  if (gravity.information <= 0.0) return terms;
  const Eigen::Matrix3d J = -R * skew(gravity.up_body);
  const Eigen::Vector3d r = R * gravity.up_body - gravity.up_frame;
  terms.H = gravity.information * J.transpose() * J;
  terms.g = gravity.information * J.transpose() * r;
  return terms;
}

}  // namespace

RegistrationResult register_scan(std::span<const Eigen::Vector3f> points, const VoxelHashMap& map,
                                 const PosePrior& prior, double max_distance_m, double kernel_scale_m,
                                 const RegistrationConfig& config) {
  return register_scan(points, map, prior, max_distance_m, kernel_scale_m, config, {});
}

RegistrationResult register_scan(std::span<const Eigen::Vector3f> points, const VoxelHashMap& map,
                                 const PosePrior& prior, double max_distance_m, double kernel_scale_m,
                                 const RegistrationConfig& config, std::span<MapPlane> planes) {
  return register_scan(points, map, prior, max_distance_m, kernel_scale_m, config, planes, SweepMotion{});
}

RegistrationResult register_scan(std::span<const Eigen::Vector3f> measured, const VoxelHashMap& map,
                                 const PosePrior& prior, double max_distance_m, double kernel_scale_m,
                                 const RegistrationConfig& config, std::span<MapPlane> planes,
                                 const SweepMotion& sweep) {
  return register_scan(measured, map, prior, max_distance_m, kernel_scale_m, config, planes, sweep, PriorMapTerm{});
}

RegistrationResult register_scan(std::span<const Eigen::Vector3f> measured, const VoxelHashMap& map,
                                 const PosePrior& prior, double max_distance_m, double kernel_scale_m,
                                 const RegistrationConfig& config, std::span<MapPlane> planes,
                                 const SweepMotion& sweep, const PriorMapTerm& prior_map) {
  RegistrationResult result;
  // A sweep to deskew: the points are redone from `measured` whenever the velocity changes.
  const bool timed = sweep.times_s.size() == measured.size() && sweep.deskewed.size() >= measured.size();
  float duration = 0.0F;
  if (timed)
    for (const float t : sweep.times_s) duration = std::max(duration, t);
  // Points all at one instant (a source without firing times) say nothing of the velocity.
  const bool estimate = timed && sweep.estimate && duration > 0.0F;
  Vector6d velocity = sweep.velocity;
  std::span<const Eigen::Vector3f> points = measured;
  TabulatedDeskewer<128> deskewer;  // on the stack: 6 kB, no allocation
  if (timed) {
    points = sweep.deskewed.first(measured.size());
    deskewer.deskew(measured, sweep.times_s, velocity, sweep.deskewed);
  }
  result.sweep_velocity = velocity;
  result.pose = prior.mean;
  // Graduated kernel: start wide enough to pull in from the prediction's
  // error, halve the scale down to the floor set by the sensor's noise (so
  // that associations made early cannot bias the end result), then iterate
  // at the floor until the update is negligible. The scale halves only once
  // an iteration's update is below config.narrow_below_step: from a good
  // prediction that is every iteration, from one that missed a turn the
  // wide kernel pulls until the pose has come in (decision 042).
  double kappa = std::max(kernel_scale_m, config.min_kernel_scale_m);
  const double data_scale = 1.0 / (config.point_sigma_m * config.point_sigma_m);
  NormalEquations ne;
  Degeneracy degeneracy;
  // The planes found for each point are kept (when `planes` has room) and
  // searched again only after the pose has moved enough to change them: the
  // search is most of the cost, and near convergence the pose moves by mm.
  Eigen::Isometry3d associated_at = result.pose;
  Vector6d associated_velocity = velocity;
  for (int iteration = 1; iteration <= config.max_iterations; ++iteration) {
    const Eigen::Isometry3d moved = associated_at.inverse() * result.pose;
    // A change of sweep velocity moves the last points of the sweep by duration·Δξ.
    const Vector6d sweep_moved = static_cast<double>(duration) * (velocity - associated_velocity);
    const bool associate = iteration == 1 ||
                           moved.translation().norm() + sweep_moved.head<3>().norm() > config.reassociate_m ||
                           Eigen::AngleAxisd(moved.linear()).angle() + sweep_moved.tail<3>().norm() > config.reassociate_rad;
    if (associate) {
      associated_at = result.pose;
      associated_velocity = velocity;
    }
    ne = build(points, map, result.pose, max_distance_m, kappa * kappa, config, planes, associate,
               estimate ? sweep.times_s : std::span<const float>{}, prior_map);
    degeneracy = analyse(ne, config.degeneracy_threshold, config.min_plane_correspondences);
    // Prior residual in the body tangent space: e = log(mean⁻¹·T), and
    // e(T·exp(δ)) ≈ e + δ to first order.
    const Vector6d e = log_se3(prior.mean.inverse() * result.pose);
    const GravityTerms gravity = gravity_terms(prior.gravity, result.pose.linear());
    Vector6d delta;
    Vector6d delta_velocity = Vector6d::Zero();
    if (estimate) {
      // Pose and sweep velocity together; the velocity prior's residual is ξ − ξ_prior.
      Matrix12d H = ne.H12 * data_scale;
      Vector12d g = ne.g12 * data_scale;
      H.topLeftCorner<6, 6>() += prior.information;
      g.head<6>() += prior.information * e;
      H.block<3, 3>(3, 3) += gravity.H;
      g.segment<3>(3) += gravity.g;
      H.bottomRightCorner<6, 6>() += sweep.information;
      g.tail<6>() += sweep.information * (velocity - sweep.velocity);
      Vector12d step = H.ldlt().solve(-g);
      if (!step.allFinite()) step.setZero();
      delta = step.head<6>();
      delta_velocity = step.tail<6>();
    } else {
      Matrix6d H = ne.H * data_scale + prior.information;
      Vector6d g = ne.g * data_scale + prior.information * e;
      H.bottomRightCorner<3, 3>() += gravity.H;
      g.tail<3>() += gravity.g;
      delta = H.ldlt().solve(-g);
      if (!delta.allFinite()) delta.setZero();
    }
    // Solution remapping: no update along directions the scan cannot see.
    delta.head<3>() = degeneracy.translation_projector * delta.head<3>();
    delta.tail<3>() = degeneracy.rotation_projector * delta.tail<3>();
    // A direction the scan cannot see in the pose it cannot see in the sweep's motion either.
    delta_velocity.head<3>() = degeneracy.translation_projector * delta_velocity.head<3>();
    delta_velocity.tail<3>() = degeneracy.rotation_projector * delta_velocity.tail<3>();
    result.pose = result.pose * exp_se3(delta);
    if (estimate) {
      velocity += delta_velocity;
      deskewer.deskew(measured, sweep.times_s, velocity, sweep.deskewed);
    }
    result.iterations = iteration;
    const bool last_level = kappa <= config.min_kernel_scale_m;
    const double step_norm = std::sqrt(delta.squaredNorm() + static_cast<double>(duration * duration) * delta_velocity.squaredNorm());
    if (last_level && step_norm < config.convergence_norm) break;
    if (step_norm < config.narrow_below_step) kappa = std::max(0.5 * kappa, config.min_kernel_scale_m);
  }
  result.sweep_velocity = velocity;
  result.correspondences = ne.count;
  result.prior_correspondences = ne.prior_count;
  result.inlier_ratio = points.empty() ? 0.0 : static_cast<double>(ne.count) / static_cast<double>(points.size());
  result.rmse_m = ne.weight_sum > 0.0 ? std::sqrt(ne.residual2_sum / ne.weight_sum) : 0.0;
  result.degenerate = degeneracy.degenerate;
  result.weakest_direction = degeneracy.weakest;
  result.weakest_eigenvalue = degeneracy.weakest_eigenvalue;

  // Covariance ≈ (H_data/σ² + Λ_prior)⁻¹, σ the larger of the configured
  // point σ and the residual RMS (Censi 2007 discusses why this is
  // optimistic); directions constrained by nothing get a large variance
  // instead of an infinite one. Solved in the body frame, reported for a
  // world-frame perturbation.
  const double sigma = std::max(config.point_sigma_m, result.rmse_m);
  Matrix6d H = ne.H / (sigma * sigma) + prior.information;
  H.bottomRightCorner<3, 3>() += gravity_terms(prior.gravity, result.pose.linear()).H;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> solver(H);
  constexpr double kUnconstrainedVariance = 1e6;
  Vector6d inverse_eigenvalues;
  for (int i = 0; i < 6; ++i) {
    const double lambda = solver.eigenvalues()(i);
    inverse_eigenvalues(i) = lambda > 1e-9 ? 1.0 / lambda : kUnconstrainedVariance;
  }
  const Matrix6d body = solver.eigenvectors() * inverse_eigenvalues.asDiagonal() * solver.eigenvectors().transpose();
  const Matrix6d Ad = adjoint(result.pose);
  result.covariance = Ad * body * Ad.transpose();
  return result;
}

}  // namespace adit::slam
