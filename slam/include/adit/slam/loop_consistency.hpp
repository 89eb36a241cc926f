#pragma once
// The false-loop guard's pairwise test and the guard itself.
//
// Pairwise consistency (after PCM, Mangelson et al., "Pairwise Consistent
// Measurement Set Maximization for Robust Multi-robot Map Merging", ICRA
// 2018, eq. 6-8): two loops a = (i → j) and b = (k → l), measured Z_a ≈ T_i⁻¹T_j
// and Z_b ≈ T_k⁻¹T_l, agree when the cycle they close with the odometry
// between their ends is near identity:
//     E = (O_ik · Z_b)⁻¹ · Z_a · O_jl,   O_ik = T_i⁻¹T_k, O_jl = T_j⁻¹T_l (the graph's estimate)
// In practice the two estimates of T_i⁻¹T_l, Z_a·O_jl and O_ik·Z_b, are
// compared in i's frame. The translation difference, less its components
// along a partial loop's unobserved axis (loop_verification.hpp), is gated
// by chi-square (3 dof, 99 %) against the two loops' σ² plus the odometry's
// accumulated σ² along i→k and j→l; the rotation by max_rotation_rad. Two wrong loops rarely agree with each other
// and with a right one: a symmetric tunnel's false match is off by a
// different amount at each keyframe.
//
// The guard: a verified loop is
//   rejected  when it disagrees with any accepted loop;
//   accepted  when it agrees with at least one other verified loop (accepted
//             or waiting), which is then accepted with it;
//   waiting   otherwise (a real revisit gives a loop at consecutive keyframes;
//             a single coincidence does not).
// The graph's robust kernel (slam/pose_graph_solver.hpp) is the last line.

#include <cstddef>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "adit/slam/lie.hpp"

namespace adit::slam {

struct LoopConstraint {
  std::size_t from = 0;  // the older keyframe (candidate)
  std::size_t to = 0;    // the newer one (query)
  Eigen::Isometry3d measurement = Eigen::Isometry3d::Identity();  // T_from⁻¹·T_to
  double sigma_m = 0.05;     // per-axis σ of its translation
  Eigen::Vector3d free_axis = Eigen::Vector3d::Zero();  // a partial loop's unobserved translation, `from`'s frame
};

struct ConsistencyConfig {
  double chi2_3dof = 11.34;          // 99 % for 3 degrees of freedom
  double max_rotation_rad = 0.05;    // ~3°
};

bool pairwise_consistent(const LoopConstraint& a, const LoopConstraint& b, std::span<const Eigen::Isometry3d> poses,
                         std::span<const double> position_variance, const ConsistencyConfig& config = {});

enum class GuardDecision { accepted, waiting, rejected };

class LoopGuard {
 public:
  explicit LoopGuard(const ConsistencyConfig& config = {}) : config_(config) {}

  // Returns the loops accepted by this submission (the new one and any
  // waiting ones it confirmed), in submission order; `decision` says what
  // became of the new one.
  std::vector<LoopConstraint> submit(const LoopConstraint& loop, std::span<const Eigen::Isometry3d> poses,
                                     std::span<const double> position_variance, GuardDecision& decision);

  const std::vector<LoopConstraint>& accepted() const { return accepted_; }
  const std::vector<LoopConstraint>& waiting() const { return waiting_; }
  std::size_t rejected() const { return rejected_; }

 private:
  ConsistencyConfig config_;
  std::vector<LoopConstraint> accepted_;
  std::vector<LoopConstraint> waiting_;
  std::size_t rejected_ = 0;
};

}  // namespace adit::slam
