#include "adit/slam/registration.hpp"

#include <cmath>

#include <Eigen/Eigenvalues>

namespace adit::slam {
namespace {

// Geman-McClure IRLS weight, normalised to 1 at zero residual:
// ρ(r) = r²/(κ² + r²)  ⇒  w(r) = ρ'(r)/r ∝ κ⁴/(κ² + r²)².
double geman_mcclure_weight(double r2, double kappa2) {
  const double d = kappa2 + r2;
  return kappa2 * kappa2 / (d * d);
}

struct NormalEquations {
  Matrix6d H = Matrix6d::Zero();
  Vector6d g = Vector6d::Zero();
  double weight_sum = 0.0;
  // The point-to-plane part alone, for the degeneracy analysis: point-to-point
  // residuals against a sparse map "constrain" every direction through the
  // sampling pattern, which would hide a tunnel's axis.
  Matrix6d H_plane = Matrix6d::Zero();
  double plane_weight_sum = 0.0;
  int plane_count = 0;
  double residual2_sum = 0.0;  // Σ w·r², robust-weighted
  int count = 0;
};

// Point-to-plane: r = n·(q − μ); ∂r/∂[v; ω] = [nᵀ, (q × n)ᵀ] for q ← exp(δ)q.
void accumulate_plane(NormalEquations& ne, const Eigen::Vector3d& q, const Eigen::Vector3d& n, double r,
                      double kappa2) {
  Vector6d J;
  J << n, q.cross(n);
  const double w = geman_mcclure_weight(r * r, kappa2);
  const Matrix6d JJ = w * J * J.transpose();
  ne.H += JJ;
  ne.H_plane += JJ;
  ne.g.noalias() += w * J * r;
  ne.weight_sum += w;
  ne.plane_weight_sum += w;
  ne.residual2_sum += w * r * r;
  ++ne.count;
  ++ne.plane_count;
}

// One pass over the points at pose T: linearised residuals and their weights.
NormalEquations build(std::span<const Eigen::Vector3f> points, const VoxelHashMap& map, const Eigen::Isometry3d& T,
                      double max_distance_m, double kappa2) {
  NormalEquations ne;
  const double max_d2 = max_distance_m * max_distance_m;
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  for (const Eigen::Vector3f& body : points) {
    const Eigen::Vector3f q = R * body + t;
    const Eigen::Vector3d qd = q.cast<double>();
    if (const VoxelPlane* plane = map.plane_at(q); plane != nullptr && (q - plane->mean).squaredNorm() <= max_d2) {
      const Eigen::Vector3d n = plane->normal.cast<double>();
      accumulate_plane(ne, qd, n, n.dot(qd - plane->mean.cast<double>()), kappa2);
      continue;
    }
    const MapNeighbor nb = map.nearest(q, static_cast<float>(max_distance_m));
    if (!nb.found) continue;
    if (!nb.normal.isZero()) {
      // The query's own voxel is not flat (or is empty) but its nearest
      // neighbour's is: point-to-plane through that neighbour.
      const Eigen::Vector3d n = nb.normal.cast<double>();
      accumulate_plane(ne, qd, n, n.dot(qd - nb.point.cast<double>()), kappa2);
      continue;
    }
    // Point-to-point where the map has no plane yet (a sparse start, clutter):
    // r = q − p; ∂r/∂[v; ω] = [I, −[q]×] (Besl & McKay 1992).
    const Eigen::Vector3d r = qd - nb.point.cast<double>();
    Eigen::Matrix<double, 3, 6> J;
    J << Eigen::Matrix3d::Identity(), -skew(qd);
    const double w = geman_mcclure_weight(r.squaredNorm(), kappa2);
    ne.H.noalias() += w * J.transpose() * J;
    ne.g.noalias() += w * J.transpose() * r;
    ne.weight_sum += w;
    ne.residual2_sum += w * r.squaredNorm();
    ++ne.count;
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
// data Hessian below the threshold are not constrained by the scan. Judged on
// the point-to-plane part when there is enough of it (see NormalEquations).
Degeneracy analyse(const NormalEquations& ne, double threshold, int min_plane_correspondences) {
  Degeneracy d;
  const bool planes = ne.plane_count >= min_plane_correspondences && ne.plane_weight_sum > 0.0;
  const Matrix6d& H = planes ? ne.H_plane : ne.H;
  const double weight_sum = planes ? ne.plane_weight_sum : ne.weight_sum;
  if (weight_sum <= 0.0) {
    d.degenerate = true;
    d.translation_projector.setZero();
    d.rotation_projector.setZero();
    d.weakest << 1, 0, 0, 0, 0, 0;
    return d;
  }
  // Per unit weight: translation eigenvalues are the share of residuals that
  // watch a direction (0..1); rotation ones are that share times the squared
  // lever arm in m², i.e. displacement per radian judged at 1 m.
  const Eigen::Matrix3d Ht = H.topLeftCorner<3, 3>() / weight_sum;
  const Eigen::Matrix3d Hr = H.bottomRightCorner<3, 3>() / weight_sum;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> et(Ht);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> er(Hr);
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

}  // namespace

RegistrationResult register_scan(std::span<const Eigen::Vector3f> points, const VoxelHashMap& map,
                                 const PosePrior& prior, double max_distance_m, double kernel_scale_m,
                                 const RegistrationConfig& config) {
  RegistrationResult result;
  result.pose = prior.mean;
  // Graduated kernel (in the spirit of GNC, Yang et al., RA-L 2020): start
  // wide enough to pull in from the prediction's error, then halve the scale
  // each time the estimate settles, down to the floor set by the sensor's
  // noise, so that wrong associations made early cannot bias the end result.
  double kappa = std::max(kernel_scale_m, config.min_kernel_scale_m);
  NormalEquations ne;
  Degeneracy degeneracy;
  for (int iteration = 1; iteration <= config.max_iterations; ++iteration) {
    ne = build(points, map, result.pose, max_distance_m, kappa * kappa);
    degeneracy = analyse(ne, config.degeneracy_threshold, config.min_plane_correspondences);
    // Prior residual in the left tangent space: e = log(T · mean⁻¹), ∂e/∂δ ≈ I.
    const Vector6d e = log_se3(result.pose * prior.mean.inverse());
    const Matrix6d H = ne.H + prior.information;
    const Vector6d g = ne.g + prior.information * e;
    Vector6d delta = H.ldlt().solve(-g);
    if (!delta.allFinite()) delta.setZero();
    // Solution remapping: no update along directions the scan cannot see.
    delta.head<3>() = degeneracy.translation_projector * delta.head<3>();
    delta.tail<3>() = degeneracy.rotation_projector * delta.tail<3>();
    result.pose = exp_se3(delta) * result.pose;
    result.iterations = iteration;
    // Wider kernels only steer: move on once they settle roughly; the final
    // kernel decides, to the full tolerance.
    const bool last_level = kappa <= config.min_kernel_scale_m;
    if (delta.norm() < (last_level ? 1.0 : 10.0) * config.convergence_norm) {
      if (last_level) break;
      kappa = std::max(0.5 * kappa, config.min_kernel_scale_m);
    }
  }
  result.correspondences = ne.count;
  result.inlier_ratio = points.empty() ? 0.0 : static_cast<double>(ne.count) / static_cast<double>(points.size());
  result.rmse_m = ne.weight_sum > 0.0 ? std::sqrt(ne.residual2_sum / ne.weight_sum) : 0.0;
  result.degenerate = degeneracy.degenerate;
  result.weakest_direction = degeneracy.weakest;
  result.weakest_eigenvalue = degeneracy.weakest_eigenvalue;

  // Covariance ≈ σ² (H_data + Λ_prior)⁻¹ with σ the residual RMS (Censi 2007
  // discusses why this is optimistic); directions constrained by nothing get
  // a large variance instead of an infinite one.
  const Matrix6d H = ne.H + prior.information;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> solver(H);
  constexpr double kUnconstrainedVariance = 1e6;
  Vector6d inverse_eigenvalues;
  for (int i = 0; i < 6; ++i) {
    const double lambda = solver.eigenvalues()(i);
    inverse_eigenvalues(i) = lambda > 1e-9 ? 1.0 / lambda : kUnconstrainedVariance;
  }
  const double sigma2 = std::max(result.rmse_m * result.rmse_m, 1e-6);
  result.covariance = sigma2 * solver.eigenvectors() * inverse_eigenvalues.asDiagonal() * solver.eigenvectors().transpose();
  return result;
}

}  // namespace adit::slam
