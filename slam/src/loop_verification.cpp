// Registration-based verification of loop candidates (loop_verification.hpp).
#include "adit/slam/loop_verification.hpp"

#include <algorithm>
#include <vector>

namespace adit::slam {

std::string_view to_string(LoopVerdict verdict) {
  switch (verdict) {
    case LoopVerdict::accepted: return "accepted";
    case LoopVerdict::partial: return "partial";
    case LoopVerdict::no_overlap: return "no_overlap";
    case LoopVerdict::poor_fit: return "poor_fit";
    case LoopVerdict::ill_conditioned: return "ill_conditioned";
    case LoopVerdict::ambiguous: return "ambiguous";
  }
  return "unknown";
}

void add_to_submap(VoxelHashMap& submap, std::span<const Eigen::Vector3f> points, const Eigen::Isometry3d& pose) {
  std::vector<Eigen::Vector3f> placed;
  placed.reserve(points.size());
  const Eigen::Isometry3f T = pose.cast<float>();
  for (const Eigen::Vector3f& p : points) placed.push_back(T * p);
  submap.add(placed);
}

namespace {

LoopVerdict judge(const RegistrationResult& r, const LoopVerificationConfig& c) {
  if (r.inlier_ratio < c.min_inlier_ratio) return LoopVerdict::no_overlap;
  if (r.rmse_m > c.max_rmse_m) return LoopVerdict::poor_fit;
  if (r.degenerate || r.weakest_eigenvalue < c.min_conditioning)
    return c.allow_partial ? LoopVerdict::partial : LoopVerdict::ill_conditioned;
  return LoopVerdict::accepted;
}

// How much a verdict says about the candidate: the order in which the worst
// failure is reported when no guess passes.
int rank(LoopVerdict v) {
  switch (v) {
    case LoopVerdict::accepted: return 5;
    case LoopVerdict::partial: return 4;
    case LoopVerdict::ambiguous: return 3;
    case LoopVerdict::ill_conditioned: return 2;
    case LoopVerdict::poor_fit: return 1;
    case LoopVerdict::no_overlap: return 0;
  }
  return 0;
}

}  // namespace

LoopVerification verify_loop(std::span<const Eigen::Vector3f> query_points, const VoxelHashMap& submap,
                             std::span<const Eigen::Isometry3d> guesses, const LoopVerificationConfig& config) {
  LoopVerification out;
  if (query_points.empty() || submap.empty() || guesses.empty()) return out;
  std::vector<RegistrationResult> passing;
  std::vector<MapPlane> planes(query_points.size());  // planes kept between iterations: searched again only after a move
  bool have_best_failure = false;
  for (const Eigen::Isometry3d& guess : guesses) {
    PosePrior prior;
    prior.mean = guess;  // information zero: the guess only starts the registration
    const RegistrationResult r =
        register_scan(query_points, submap, prior, config.max_distance_m, config.kernel_scale_m, config.registration, planes);
    const LoopVerdict v = judge(r, config);
    if (v == LoopVerdict::accepted || v == LoopVerdict::partial) {
      passing.push_back(r);
    } else if (!have_best_failure || rank(v) > rank(out.verdict) ||
               (rank(v) == rank(out.verdict) && r.inlier_ratio > out.registration.inlier_ratio)) {
      out.verdict = v;
      out.registration = r;
      have_best_failure = true;
    }
  }
  out.passing_guesses = static_cast<int>(passing.size());
  if (passing.empty()) return out;
  if (config.heading_gate_rad > 0.0) {
    const auto outside = [&](const RegistrationResult& r) {
      return Eigen::AngleAxisd(guesses.front().linear().transpose() * r.pose.linear()).angle() > config.heading_gate_rad;
    };
    const auto inside_count = std::count_if(passing.begin(), passing.end(), [&](const auto& r) { return !outside(r); });
    if (inside_count > 0) {
      out.set_aside = static_cast<int>(passing.size()) - static_cast<int>(inside_count);
      std::erase_if(passing, outside);
    }
  }
  // The best-fitting solution, then: does another passing one disagree with it?
  std::size_t best = 0;
  for (std::size_t i = 1; i < passing.size(); ++i)
    if (passing[i].inlier_ratio > passing[best].inlier_ratio) best = i;
  const RegistrationResult& r = passing[best];
  out.registration = passing[best];
  out.relative = passing[best].pose;
  for (const RegistrationResult& other : passing) {
    const Eigen::Isometry3d d = passing[best].pose.inverse() * other.pose;
    if (d.translation().norm() > config.ambiguity_m || Eigen::AngleAxisd(d.linear()).angle() > config.ambiguity_rad) {
      out.verdict = LoopVerdict::ambiguous;
      return out;
    }
  }
  out.verdict = judge(r, config);
  // Information in the registration's body-frame perturbation δ (the query's
  // frame, T·exp(δ)), fixed σ, with a partial loop's weakest direction w
  // projected out: Λ_δ = (I − wwᵀ) Λ (I − wwᵀ).
  Vector6d diagonal;
  diagonal << Eigen::Vector3d::Constant(1.0 / (config.covariance_sigma_m * config.covariance_sigma_m)),
      Eigen::Vector3d::Constant(1.0 / (config.covariance_sigma_rad * config.covariance_sigma_rad));
  Matrix6d information = diagonal.asDiagonal();
  const Eigen::Matrix3d R = r.pose.linear();
  if (out.verdict == LoopVerdict::partial) {
    const Vector6d w = r.weakest_direction.normalized();
    const Matrix6d P = Matrix6d::Identity() - w * w.transpose();
    information = P * information * P;
    if (w.head<3>().norm() > 0.5) out.free_axis = (R * w.head<3>()).normalized();
  }
  // The graph's residual is e = [R·δ_v; δ_ω] to first order (Ẑ = Z·exp(δ)),
  // e = J·δ with J = diag(R, I): Λ_e = J⁻ᵀ Λ_δ J⁻¹, J⁻¹ = diag(Rᵀ, I).
  Matrix6d J_inv = Matrix6d::Identity();
  J_inv.topLeftCorner<3, 3>() = R.transpose();
  out.information = J_inv.transpose() * information * J_inv;
  return out;
}

}  // namespace adit::slam
