#pragma once
// Loop candidates for a new keyframe: old keyframes the pose graph says it
// could be at, whose Scan Context looks like the new one's.
//
// Two gates, both needed (docs/decisions/021-loop-closure-scan-context.md):
// 1. Position, by the graph's own uncertainty: the candidate's estimated
//    position lies within base_radius_m + gate_sigmas·σ of the query's, σ the
//    odometry's accumulated per-axis position σ along the path between them
//    (the chain's variance: an upper bound once loops have tied the graph,
//    so the gate is never narrower than the truth allows). A revisit the
//    odometry cannot have drifted into is not sought, however alike it looks;
//    in a repetitive mine that is most of the false matches.
// 2. Appearance: ring keys (yaw-free, cheap) keep the nearest few, the full
//    shift-searched Scan Context distance decides (Kim & Kim, IROS 2018, §III-C).
// A candidate also lies at least min_path_separation_m back along the path,
// so the keyframes just behind are not "revisits".

#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "adit/slam/scan_context.hpp"

namespace adit::slam {

struct PlaceRecognitionConfig {
  double min_path_separation_m = 30.0;
  double base_radius_m = 3.0;        // Scan Context matches within a few metres of the same spot
  double gate_sigmas = 3.0;
  int ring_key_candidates = 10;       // kept by ring key before the full comparison
  double max_descriptor_distance = 0.35;  // eq. 6's distance; the paper's working range is 0.1-0.4
  int max_candidates = 3;             // best by descriptor distance
};

struct LoopCandidate {
  std::size_t query = 0;       // the new keyframe
  std::size_t candidate = 0;   // the old one
  double descriptor_distance = 1.0;
  double yaw_rad = 0.0;                // R_candidate⁻¹·R_query about z, from the best column shift
  double alternative_yaw_rad = 0.0;    // the best shift ≥ 90° away (a symmetric tunnel's other reading)
  double alternative_distance = 1.0;   // its descriptor distance
  double gap_m = 0.0;                  // between the two estimated positions
};

// What the search sees of each keyframe up to the query (index = keyframe).
// The full descriptors of old keyframes are read only for the few their ring
// keys keep (they may lie on disk: slam/keyframe_scan_store.hpp).
struct KeyframeIndexView {
  std::span<const Eigen::VectorXf> ring_keys;   // ScanContext::ring_key
  std::span<const Eigen::Isometry3d> poses;     // the graph's current estimate
  std::span<const double> path_m;               // path length from the first keyframe
  std::span<const double> position_variance;    // accumulated odometry σ² per axis from the first keyframe
};

// Fills `bins` with keyframe k's ScanContext::bins; false when they cannot be
// had (that keyframe is passed over; the reader says why).
using DescriptorReader = std::function<bool(std::size_t k, Eigen::MatrixXf& bins)>;

std::vector<LoopCandidate> find_loop_candidates(std::size_t query, const ScanContext& query_descriptor,
                                                const KeyframeIndexView& keyframes,
                                                const DescriptorReader& read_descriptor,
                                                const PlaceRecognitionConfig& config = {});

}  // namespace adit::slam
