#pragma once
// The map→odometry correction through time: at each keyframe k the graph's
// pose G_k against the pose O_k the map was built at, C_k = G_k·O_k⁻¹; between
// two keyframes C is interpolated on SE(3) (C_a·exp(s·log(C_a⁻¹·C_b))), beyond
// the ends it is held. A map point measured at time t moves to C(t)·p: the
// map follows the graph without its scans being kept (each map sample carries
// its scan's time, slam/tiled_map.hpp).

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "adit/slam/lie.hpp"
#include "adit/slam/tiled_map.hpp"
#include "adit/slam/trajectory.hpp"

namespace adit::slam {

class CorrectionTrack {
 public:
  CorrectionTrack() = default;
  // `stamps_ns` increasing; `graph` and `odometry` as long.
  CorrectionTrack(std::span<const std::int64_t> stamps_ns, std::span<const Eigen::Isometry3d> graph,
                  std::span<const Eigen::Isometry3d> odometry);

  Eigen::Isometry3d at(std::int64_t stamp_ns) const;
  bool empty() const { return stamps_.empty(); }
  // The largest correction over the keyframes: translation (m) and rotation (rad).
  double max_translation_m() const;
  double max_rotation_rad() const;
  const std::vector<Eigen::Isometry3d>& corrections() const { return corrections_; }
  // The keyframes' stamps and where the graph puts them (G_k's translation):
  // the path a client draws with the corrected map.
  const std::vector<std::int64_t>& stamps_ns() const { return stamps_; }
  const std::vector<Eigen::Vector3d>& graph_positions() const { return positions_; }

  // The same track at every scan time of `samples` (at() gives the same
  // bits), holding only the keyframes that bracket those times: what a live
  // tile sent placed by it must remember, a few of the session's keyframes.
  // Elsewhere it is an interpolation between the keyframes kept.
  CorrectionTrack slice_for(std::span<const MapSample> samples) const;
  // Two slices of one track (slice_for of two sets of samples) as one: the
  // same track at the times of both sets (a tile's earlier points and those
  // it gained since).
  CorrectionTrack merged_with(const CorrectionTrack& other) const;

 private:
  std::vector<std::int64_t> stamps_;
  std::vector<Eigen::Vector3d> positions_;
  std::vector<Eigen::Isometry3d> corrections_;
  std::vector<Vector6d> steps_;  // log(C_k⁻¹·C_k+1)
};

// `track`, made against the poses the map was built at (`built_at`, M), for
// other poses of the same motion (`poses`, P: the odometry's, which the map's
// refinement moved to M): at each of their stamps t the correction
// C(t)·M(t)·P(t)⁻¹, M interpolated between built_at's poses and held beyond
// its ends, so P(t) goes where the graph put the map's pose at t. `track`
// alone would move P(t) by C(t) and keep the refinement's difference
// M(t)·P(t)⁻¹ out (tenths of a metre after a few minutes). Empty when
// `track` or `built_at` is.
CorrectionTrack retargeted(const CorrectionTrack& track, const Trajectory& built_at, const Trajectory& poses);

// The map following the graph: `in` into `out`, each sample moved by
// placed_by·C(t) at its scan's time t (C: `track`, identity when null). The
// correction is computed once per run of samples of one scan.
void correct_samples(std::span<const MapSample> in, const CorrectionTrack* track, const Eigen::Isometry3d& placed_by,
                     std::vector<MapSample>& out);

// Whether any of `samples` is placed more than `min_move_m` apart by the
// correction `a` and by `b` (either null: identity): a live tile sent placed
// by `a` that must be sent again placed by `b`. Stops at the first such sample.
bool correction_moves(std::span<const MapSample> samples, const CorrectionTrack* a, const CorrectionTrack* b,
                      double min_move_m);

// A cheap gate before correction_moves, without the samples: whether going
// from `a` (slice_for of samples inside `box`, none newer than `newest_s`) to
// `b` (null: identity) could move one of them by more than `min_move_m`.
// At one time the move is affine in the point, so its largest over the box is
// at a corner. The corners are moved at a's keyframes, midway between them,
// and at b's keyframes after a's last up to newest_s (a holds its last
// correction there). False only when none moves more than half of
// min_move_m, the slack for the times between; true when `a` is empty (its
// samples' times are not known).
bool correction_may_move(const CorrectionTrack& a, const CorrectionTrack* b, const Eigen::AlignedBox3d& box,
                         double newest_s, double min_move_m);

}  // namespace adit::slam
