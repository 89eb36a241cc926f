#pragma once
// Loop detection against the simulator's truth (`adit eval loops`, docs/LOOPS.md
// "Measured"): which keyframes truly revisit a place, which accepted loops are
// false, precision, recall and the accepted loops' error.
//
// A true revisit: keyframe q lies within `revisit_m` of an earlier keyframe c
// by their TRUE positions (truth_body.tum interpolated at the keyframes'
// stamps) and at least `min_path_m` before it along the true path (the loop
// closer's own minimum, slam/place_recognition.hpp). Overlap is approximated
// by distance alone, heading-free: a 360° LiDAR sees the same walls from a
// place whichever way it faces, and the closer matches reverse revisits.
//
// An accepted loop is false when its keyframes' true positions are more than
// `false_beyond_m` apart, or when its measured relative pose differs from the
// true one by more than `max_error_m` / `max_error_deg`. A partial loop (its
// information singular along a translation, slam/loop_verification.hpp) is
// judged on the error across that free axis: along it the loop carries no
// information and cannot move the graph; its whole error is reported too.
//
// Recall: the share of revisit keyframes q with a true accepted loop whose later
// keyframe (the query) lies within ±`window` keyframes of q.

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "adit/eval/stats.hpp"
#include "adit/slam/lie.hpp"
#include "adit/slam/trajectory.hpp"

namespace adit::eval {

// One loop in the graph: measures T_from⁻¹·T_to (from = the earlier keyframe).
struct LoopEdgeRecord {
  std::size_t from = 0;
  std::size_t to = 0;
  slam::Pose measurement = slam::Pose::Identity();
  slam::Matrix6d information = slam::Matrix6d::Identity();  // of e = [p; θ] in from's frame
};

// A partial loop's unobserved translation (unit, from's frame): the null
// direction of its information when that is mostly translation.
std::optional<Eigen::Vector3d> free_axis(const slam::Matrix6d& information);

struct LoopTruthConfig {
  double revisit_m = 3.0;
  double min_path_m = 30.0;
  double false_beyond_m = 10.0;
  double max_error_m = 0.3;
  double max_error_deg = 1.0;
  std::size_t window = 5;
};

// The truth at each keyframe: pose and distance along the true path.
struct KeyframeTruth {
  std::vector<slam::Pose> poses;
  std::vector<double> path_m;
};

// Interpolates `truth` at `stamps` (s); a stamp outside the truth's span
// throws InputError naming `truth_name` and the keyframe.
KeyframeTruth keyframe_truth(const slam::Trajectory& truth, std::span<const double> stamps,
                             const std::string& truth_name);

struct LoopCheck {
  LoopEdgeRecord loop;
  bool partial = false;
  double truth_distance_m = 0.0;  // between the two keyframes' true positions
  double truth_path_m = 0.0;      // between them along the true path
  double error_m = 0.0;           // |measured − true| translation, from's frame
  double error_judged_m = 0.0;    // the same across the free axis (= error_m when not partial)
  double error_deg = 0.0;
  bool is_false = false;
};

// [first, last] keyframes of a run of consecutive revisit keyframes: one place.
struct Stretch {
  std::size_t first = 0;
  std::size_t last = 0;
};

struct LoopTruthReport {
  std::size_t keyframes = 0;
  std::vector<std::size_t> revisit_keyframes;
  std::vector<Stretch> revisit_stretches;
  std::size_t recalled_keyframes = 0;
  std::size_t recalled_stretches = 0;  // with at least one recalled keyframe
  std::vector<LoopCheck> loops;
  std::size_t false_loops = 0;
  std::optional<double> precision;  // true accepted / accepted; none when nothing was accepted
  std::optional<double> recall;     // recalled / revisit keyframes; none when there is no revisit
  Stats error_m;                    // of the true loops' error_judged_m
  Stats error_deg;
};

// Throws InputError(where = `loops_name`) when a loop names a keyframe that
// does not exist.
LoopTruthReport evaluate_loops(const KeyframeTruth& truth, std::span<const LoopEdgeRecord> loops,
                               const LoopTruthConfig& config, const std::string& loops_name = "loops");

}  // namespace adit::eval
