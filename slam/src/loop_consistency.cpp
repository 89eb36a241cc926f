// Pairwise loop consistency and the false-loop guard (loop_consistency.hpp).
#include "adit/slam/loop_consistency.hpp"

#include <algorithm>
#include <cmath>

namespace adit::slam {
namespace {

double chain_variance(std::span<const double> variance, std::size_t a, std::size_t b) {
  return std::abs(variance[std::max(a, b)] - variance[std::min(a, b)]);
}

}  // namespace

bool pairwise_consistent(const LoopConstraint& a, const LoopConstraint& b, std::span<const Eigen::Isometry3d> poses,
                         std::span<const double> position_variance, const ConsistencyConfig& config) {
  const std::size_t n = std::min(poses.size(), position_variance.size());
  if (a.from >= n || a.to >= n || b.from >= n || b.to >= n) return false;
  const Eigen::Isometry3d O_ik = poses[a.from].inverse() * poses[b.from];
  const Eigen::Isometry3d O_jl = poses[a.to].inverse() * poses[b.to];
  const Eigen::Isometry3d E = (O_ik * b.measurement).inverse() * a.measurement * O_jl;
  const double variance = a.sigma_m * a.sigma_m + b.sigma_m * b.sigma_m +
                          chain_variance(position_variance, a.from, b.from) +
                          chain_variance(position_variance, a.to, b.to);
  const double mahalanobis2 = E.translation().squaredNorm() / variance;
  return mahalanobis2 <= config.chi2_3dof && Eigen::AngleAxisd(E.linear()).angle() <= config.max_rotation_rad;
}

std::vector<LoopConstraint> LoopGuard::submit(const LoopConstraint& loop, std::span<const Eigen::Isometry3d> poses,
                                              std::span<const double> position_variance, GuardDecision& decision) {
  std::vector<LoopConstraint> newly;
  bool confirmed = false;
  for (const LoopConstraint& a : accepted_) {
    if (!pairwise_consistent(loop, a, poses, position_variance, config_)) {
      ++rejected_;
      decision = GuardDecision::rejected;
      return newly;
    }
    confirmed = true;
  }
  std::vector<LoopConstraint> still_waiting;
  for (const LoopConstraint& w : waiting_) {
    const bool agrees_with_accepted = std::all_of(accepted_.begin(), accepted_.end(), [&](const LoopConstraint& a) {
      return pairwise_consistent(w, a, poses, position_variance, config_);
    });
    if (agrees_with_accepted && pairwise_consistent(loop, w, poses, position_variance, config_)) {
      newly.push_back(w);
      confirmed = true;
    } else {
      still_waiting.push_back(w);
    }
  }
  if (!confirmed) {
    waiting_.push_back(loop);
    decision = GuardDecision::waiting;
    return {};
  }
  waiting_ = std::move(still_waiting);
  newly.push_back(loop);
  accepted_.insert(accepted_.end(), newly.begin(), newly.end());
  decision = GuardDecision::accepted;
  return newly;
}

}  // namespace adit::slam
