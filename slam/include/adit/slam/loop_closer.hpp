#pragma once
// Loop closure over keyframes, one keyframe at a time: Scan Context place
// recognition gated by the graph's uncertainty (place_recognition.hpp),
// verification by registration (loop_verification.hpp), the false-loop guard
// (loop_consistency.hpp) and the Ceres pose graph (pose_graph_solver.hpp).
// Pure and single-threaded: aditd runs it on its own low-priority thread
// (daemon/src/loop_closure_stage.cpp); tests and tools call it directly.
//
// The keyframes' poses come from the mapping stage (its refined "map" poses,
// called odometry here: the frame the graph corrects). The graph's estimate
// of keyframe k, G_k, starts as G_{k-1}·(O_{k-1}⁻¹·O_k); the correction
// map→odometry is G_k·O_k⁻¹ of the newest keyframe.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "adit/slam/correction_track.hpp"
#include "adit/slam/keyframe_scan_store.hpp"
#include "adit/slam/loop_consistency.hpp"
#include "adit/slam/loop_verification.hpp"
#include "adit/slam/place_recognition.hpp"
#include "adit/slam/pose_graph.hpp"
#include "adit/slam/pose_graph_solver.hpp"
#include "adit/slam/scan_context.hpp"

namespace adit::slam {

// Verification with the heading gate (LoopVerificationConfig::heading_gate_rad):
// Scan Context's other reading lies ≥ 90° away, the graph's heading within a
// few degrees over a session (σ_r ≈ 1.5 mrad a keyframe: 3.6° over the 1,729
// keyframes of a 30-minute drive); 45° lies between them.
inline LoopVerificationConfig gated_verification() {
  LoopVerificationConfig config;
  config.heading_gate_rad = M_PI / 4;
  return config;
}

struct LoopClosureConfig {
  ScanContextConfig descriptor;
  PlaceRecognitionConfig search;
  LoopVerificationConfig verification = gated_verification();
  ConsistencyConfig consistency;
  PoseGraphSolverConfig solver;
  OdometryNoise odometry;
  int submap_keyframes = 5;          // each side of the candidate go into its submap
  // Keyframe scans and descriptors kept in RAM (the newest); older ones go to
  // the folder given to spill_scans_to() (none: all stay in RAM).
  std::size_t scans_in_ram = 200;
  // Candidates' events kept whole (LoopCloser::events()); beyond, only counted
  // by outcome: ~100 B each, an hour's drive tries ~9,000 candidates.
  std::size_t events_kept = 1000;
  float points_voxel_m = 0.3F;       // the keyframe's scan is kept downsampled at this (submaps)
  float query_voxel_m = 0.6F;        // and registered downsampled at this (about the odometry's registration points)
  // > 0: a roll/pitch prior per keyframe holding the up its pose holds
  // (R⁻¹·e_z in the body frame: with an accelerometer the map's poses hold
  // gravity, decision 008).
  double gravity_sigma_rad = 0.0;
  double tilt_walk_rad_per_sqrt_s = 0.0;  // the ups' tilt walk (PoseGraph::tilt_walk_rad_per_sqrt_s)
  // Loops accepted less than this (keyframe stamps) after the last
  // optimisation wait for the first keyframe this long after it, and are
  // solved together; refine() solves what still waits. A solve of the whole
  // graph costs what it costs whether it holds one new loop or ten, and a
  // route driven again closes a loop at nearly every keyframe (Cartographer
  // optimises every n nodes, hdl_graph_slam every few seconds, for the same
  // reason). 0 = after every keyframe that adds a loop. Decision 062.
  double optimize_every_s = 0.0;
  // A keyframe mapped while the odometry was anchored to a prior map
  // (add_keyframe's `anchored`) is held where it was mapped with these σ: the
  // anchored odometry lies within 1-2 cm of the prior (docs/PRIOR-MAP.md). The
  // loops then bring the keyframes mapped before the anchor towards the
  // anchored ones, instead of carrying the first keyframe's offset onto them.
  double anchored_sigma_m = 0.02;
  double anchored_sigma_rad = 0.0035;  // 0.2°
};

// One candidate's fate, for the log and summary.json.
struct LoopEvent {
  std::size_t query = 0;
  std::size_t candidate = 0;
  double descriptor_distance = 0.0;
  // A refused LoopVerdict's name, or the guard's decision when verified: "accepted", "waiting" (for a
  // witness: accepted later if one agrees, see LoopCloser::unconfirmed()), "inconsistent"; "_partial" appended.
  std::string outcome;
  double inlier_ratio = 0.0;
  double rmse_m = 0.0;
  double conditioning = 0.0;
};

struct LoopClosureStats {
  std::size_t keyframes = 0;
  std::size_t keyframes_not_searched = 0;  // added with search = false (the caller was behind)
  std::size_t candidates = 0;             // found by place recognition
  std::size_t verified = 0;               // passed registration
  std::size_t partial = 0;                // of which partial (one direction unobserved)
  std::size_t accepted = 0;               // in the graph
  std::size_t rejected_verification = 0;  // failed registration (overlap, fit, conditioning, ambiguity)
  std::size_t rejected_unreadable = 0;    // a candidate's scan or descriptor could not be read back (KeyframeScanStore)
  std::size_t set_aside_readings = 0;     // passing readings outside the heading gate, set aside
  std::size_t rejected_inconsistent = 0;  // failed the guard
  std::size_t optimizations = 0;
  double last_optimization_s = 0.0;
  double optimization_s_total = 0.0;      // the solver's time, all optimisations
  int last_optimization_iterations = 0;
  std::size_t optimization_iterations_total = 0;
  // Cost (CPU of the calling thread's wall clock): descriptor and candidate
  // search per keyframe, and verification per candidate.
  double search_s_total = 0.0;
  double search_s_max = 0.0;
  double verification_s_total = 0.0;
  double verification_s_max = 0.0;
};

class LoopCloser {
 public:
  explicit LoopCloser(const LoopClosureConfig& config = {});

  // Adds a keyframe (`points` in its body frame) and closes what loops it
  // can. Returns true when the graph was optimised (the poses moved): when
  // loops wait and config.optimize_every_s has passed since the last time.
  // With `search` false the keyframe joins the graph and the store (a later
  // one may find it) but seeks no loop and no optimisation runs: a caller
  // that has fallen behind catches up at a few milliseconds a keyframe.
  // `anchored`: the pose was registered against a prior map as well, so it
  // is held there (LoopClosureConfig::anchored_sigma_m).
  bool add_keyframe(std::int64_t stamp_ns, const Eigen::Isometry3d& odometry_pose,
                    std::span<const Eigen::Vector3f> points, bool search = true, bool anchored = false);

  // The graph's estimate of every keyframe, in order.
  const std::vector<Eigen::Isometry3d>& poses() const { return graph_.nodes; }
  const std::vector<Eigen::Isometry3d>& odometry_poses() const { return odometry_; }
  const std::vector<std::int64_t>& stamps() const { return stamps_; }
  // map→odometry: G·O⁻¹ of the newest keyframe (identity before any loop).
  Eigen::Isometry3d correction() const;
  // G·O⁻¹ through time (slam/correction_track.hpp), for every map point.
  CorrectionTrack correction_track() const { return CorrectionTrack(stamps_, graph_.nodes, odometry_); }
  const LoopClosureStats& stats() const { return stats_; }
  // Verified loops still waiting for a witness (never in the graph unless one comes).
  std::size_t unconfirmed() const { return guard_.waiting().size(); }
  // Loops in the graph not yet optimised (config.optimize_every_s).
  std::size_t unsolved() const { return unsolved_; }
  // The first config.events_kept candidates' events; outcomes() counts every one's.
  const std::vector<LoopEvent>& events() const { return events_; }
  const std::map<std::string, std::size_t>& outcomes() const { return outcomes_; }
  const PoseGraph& graph() const { return graph_; }
  // A last optimisation of the whole graph (session end).
  void refine();
  // Before the first keyframe: keyframe scans and descriptors beyond
  // config.scans_in_ram go to `folder` (slam/keyframe_scan_store.hpp).
  void spill_scans_to(const std::filesystem::path& folder) { scans_.spill_to(folder); }
  const KeyframeScanStore& scans() const { return scans_; }

 private:
  void try_candidate(const LoopCandidate& candidate);
  void record(const PoseGraphSolution& solution);  // its figures; nothing waits any more
  void record_event(LoopEvent event);  // counted by outcome; kept while fewer than config.events_kept

  LoopClosureConfig config_;
  PoseGraph graph_;
  LoopGuard guard_;
  std::vector<Eigen::Isometry3d> odometry_;
  std::vector<std::int64_t> stamps_;
  KeyframeScanStore scans_;  // each keyframe's scan at points_voxel_m (submaps) and its descriptor's bins
  std::vector<Eigen::Vector3f> query_points_;  // the newest keyframe's at query_voxel_m: only it is ever a query
  ScanContext query_descriptor_;               // the newest keyframe's
  std::vector<Eigen::Vector3f> neighbour_;     // a submap keyframe's scan, read back
  std::vector<Eigen::VectorXf> ring_keys_;     // every keyframe's: the search's first stage
  std::vector<double> path_m_;
  std::vector<double> variance_;
  LoopClosureStats stats_;
  std::vector<LoopEvent> events_;
  std::map<std::string, std::size_t> outcomes_;
  struct PendingInformation {
    std::size_t query, candidate;
    Matrix6d information;
  };
  std::vector<PendingInformation> information_;  // of the verified loops waiting in the guard
  std::size_t unsolved_ = 0;                     // loops added since the last optimisation
  std::int64_t last_optimization_stamp_ns_ = 0;  // the keyframe stamp it ran at
};

}  // namespace adit::slam
