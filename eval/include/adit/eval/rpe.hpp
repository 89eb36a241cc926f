#pragma once
// Relative pose error (Sturm et al., IROS 2012, sec. VI-A): for a pair (i, j)
// of matched poses, E_ij = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j), reference Q and
// estimate P; the translation error is |trans(E_ij)|, the rotation error the
// angle of rot(E_ij). Pairs are chosen by a delta in frames, metres of path
// or seconds along one of the two trajectories: the estimate by default, as
// evo does (the published KITTI 00 values are reproduced only that way).

#include <cstddef>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "adit/eval/path.hpp"
#include "adit/eval/pose_error.hpp"
#include "adit/slam/trajectory.hpp"

namespace adit::eval {

enum class DeltaUnit { frames, metres, seconds };

// "frames"/"f", "m"/"metres"/"meters", "s"/"seconds"; nullopt otherwise.
std::optional<DeltaUnit> parse_delta_unit(std::string_view name);
std::string_view delta_unit_name(DeltaUnit unit);

struct RpeSettings {
  double delta = 1.0;
  DeltaUnit unit = DeltaUnit::frames;
  // false: consecutive pairs, each starting where the previous ended;
  // true: one pair from every pose (the closest match of delta, within the tolerance).
  bool all_pairs = false;
  double relative_tolerance = 0.1;  // all pairs, metres and seconds: accept |d - delta| <= tol * delta
};

// Pairs along one trajectory: `distances` from path_distances() of its poses,
// `stamps` its times (seconds). Consecutive pairs, by unit:
//   frames   0, delta, 2 delta, ...
//   metres   i_0 is the first pose where the path from pose 0 reaches delta,
//            then each next index is where the path since the previous one
//            reaches delta again (as evo's filter_pairs_by_path does)
//   seconds  0, then each first pose at least delta seconds after the previous
// All pairs: (i, j) with j the pose whose path length / time from i is
// closest to delta (binary search on the prefix sums).
std::vector<IndexPair> rpe_pairs(std::span<const double> distances, std::span<const double> stamps,
                                 const RpeSettings& settings);

// The same all-pairs result by a linear scan from every pose: O(n^2), the
// baseline the benchmark compares against.
std::vector<IndexPair> rpe_pairs_all_naive(std::span<const double> values, double delta, double tolerance);

PoseErrors relative_pose_errors(std::span<const slam::Pose> ref, std::span<const slam::Pose> est, std::span<const IndexPair> pairs);

}  // namespace adit::eval
