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
  const Eigen::Isometry3d via_a = a.measurement * O_jl;  // T_i⁻¹T_l through loop a
  const Eigen::Isometry3d via_b = O_ik * b.measurement;  // and through loop b
  Eigen::Vector3d d = via_a.translation() - via_b.translation();
  // What a partial loop cannot tell does not count against it (Gram-Schmidt
  // over the unobserved axes, both in i's frame).
  Eigen::Vector3d axes[2] = {a.free_axis, O_ik.linear() * b.free_axis};
  Eigen::Vector3d removed[2];
  int n_removed = 0;
  for (Eigen::Vector3d f : axes) {
    for (int r = 0; r < n_removed; ++r) f -= f.dot(removed[r]) * removed[r];
    if (f.norm() < 0.1) continue;
    f.normalize();
    d -= d.dot(f) * f;
    removed[n_removed++] = f;
  }
  const double variance = a.sigma_m * a.sigma_m + b.sigma_m * b.sigma_m +
                          chain_variance(position_variance, a.from, b.from) +
                          chain_variance(position_variance, a.to, b.to);
  const double mahalanobis2 = d.squaredNorm() / variance;
  const double angle = Eigen::AngleAxisd(via_a.linear().transpose() * via_b.linear()).angle();
  return mahalanobis2 <= config.chi2_3dof && angle <= config.max_rotation_rad;
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
