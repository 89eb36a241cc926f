// Registration-based verification of loop candidates (loop_verification.hpp).
#include "adit/slam/loop_verification.hpp"

#include <vector>

namespace adit::slam {

std::string_view to_string(LoopVerdict verdict) {
  switch (verdict) {
    case LoopVerdict::accepted: return "accepted";
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
  if (r.degenerate || r.weakest_eigenvalue < c.min_conditioning) return LoopVerdict::ill_conditioned;
  return LoopVerdict::accepted;
}

// How much a verdict says about the candidate: the order in which the worst
// failure is reported when no guess passes.
int rank(LoopVerdict v) {
  switch (v) {
    case LoopVerdict::accepted: return 4;
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
    if (v == LoopVerdict::accepted) {
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
  // The best-fitting solution, then: does another passing one disagree with it?
  std::size_t best = 0;
  for (std::size_t i = 1; i < passing.size(); ++i)
    if (passing[i].inlier_ratio > passing[best].inlier_ratio) best = i;
  out.registration = passing[best];
  out.relative = passing[best].pose;
  for (const RegistrationResult& other : passing) {
    const Eigen::Isometry3d d = passing[best].pose.inverse() * other.pose;
    if (d.translation().norm() > config.ambiguity_m || Eigen::AngleAxisd(d.linear()).angle() > config.ambiguity_rad) {
      out.verdict = LoopVerdict::ambiguous;
      return out;
    }
  }
  out.verdict = LoopVerdict::accepted;
  // The registration's covariance is for a left perturbation of the pose in
  // the submap's (the candidate's) frame: the graph's loop edge is T_c⁻¹·T_q
  // in the same frame. Floored per axis.
  Vector6d floor;
  floor << Eigen::Vector3d::Constant(config.covariance_floor_m * config.covariance_floor_m),
      Eigen::Vector3d::Constant(config.covariance_floor_rad * config.covariance_floor_rad);
  out.covariance = passing[best].covariance + Matrix6d(floor.asDiagonal());
  return out;
}

}  // namespace adit::slam
