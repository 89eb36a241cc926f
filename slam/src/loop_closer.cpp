// Keyframe-by-keyframe loop closure (loop_closer.hpp).
#include "adit/slam/loop_closer.hpp"

#include <algorithm>
#include <cmath>

#include "adit/common/clock.hpp"
#include "adit/slam/voxel_downsample.hpp"

namespace adit::slam {
namespace {

Eigen::Isometry3d yawed(const Eigen::Isometry3d& guess, double yaw_rad) {
  Eigen::Isometry3d g = guess;
  g.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return g;
}

double yaw_of(const Eigen::Isometry3d& T) { return std::atan2(T.linear()(1, 0), T.linear()(0, 0)); }

}  // namespace

LoopCloser::LoopCloser(const LoopClosureConfig& config)
    : config_(config), guard_(config.consistency), scans_(config.scans_in_ram) {
  graph_.tilt_walk_rad_per_sqrt_s = config.tilt_walk_rad_per_sqrt_s;
}

bool LoopCloser::add_keyframe(std::int64_t stamp_ns, const Eigen::Isometry3d& odometry_pose,
                              std::span<const Eigen::Vector3f> points, bool search, bool anchored) {
  const std::size_t k = graph_.nodes.size();
  const std::int64_t search_start_ns = monotonic_ns();
  std::vector<Eigen::Vector3f> kept, query;  // query: only when it will be one
  kept.reserve(points.size());
  VoxelDownsampler downsampler(points.size());
  downsampler.downsample(points, config_.points_voxel_m, kept);
  if (search) {
    query.reserve(points.size());
    downsampler.downsample(points, config_.query_voxel_m, query);
  }
  ScanContext descriptor = make_scan_context(points, config_.descriptor);
  ring_keys_.push_back(descriptor.ring_key);
  if (k == 0) {
    graph_.nodes.push_back(odometry_pose);
    path_m_.push_back(0.0);
    variance_.push_back(0.0);
  } else {
    const Eigen::Isometry3d motion = odometry_.back().inverse() * odometry_pose;
    graph_.nodes.push_back(graph_.nodes.back() * motion);
    const Matrix6d information = odometry_information(motion, config_.odometry);
    graph_.edges.push_back({k - 1, k, motion, information, EdgeKind::odometry});
    path_m_.push_back(path_m_.back() + motion.translation().norm());
    variance_.push_back(variance_.back() + 1.0 / information(0, 0));
  }
  if (config_.gravity_sigma_rad > 0.0) {
    const Eigen::Vector3d up_body = odometry_pose.linear().transpose() * Eigen::Vector3d::UnitZ();
    graph_.gravity.push_back(
        {k, up_body, 1.0 / (config_.gravity_sigma_rad * config_.gravity_sigma_rad), 1e-9 * static_cast<double>(stamp_ns)});
  }
  if (anchored) {
    Matrix6d information = Matrix6d::Zero();
    information.diagonal() << Eigen::Vector3d::Constant(1.0 / (config_.anchored_sigma_m * config_.anchored_sigma_m)),
        Eigen::Vector3d::Constant(1.0 / (config_.anchored_sigma_rad * config_.anchored_sigma_rad));
    graph_.absolute.push_back({k, odometry_pose, information});
  }
  odometry_.push_back(odometry_pose);
  stamps_.push_back(stamp_ns);
  scans_.add(std::move(kept), descriptor.bins);
  query_points_ = std::move(query);
  query_descriptor_ = std::move(descriptor);
  ++stats_.keyframes;
  if (!search) {
    ++stats_.keyframes_not_searched;
    return false;
  }

  const KeyframeIndexView view{ring_keys_, graph_.nodes, path_m_, variance_};
  // An old keyframe whose file cannot be read is passed over, as its scan would be.
  const auto read_descriptor = [this, k](std::size_t j, Eigen::MatrixXf& bins) {
    if (scans_.read_descriptor(j, bins)) return true;
    ++stats_.rejected_unreadable;
    record_event({k, j, 1.0, "keyframe_unreadable", 0.0, 0.0, 0.0});
    return false;
  };
  const std::vector<LoopCandidate> candidates =
      find_loop_candidates(k, query_descriptor_, view, read_descriptor, config_.search);
  stats_.candidates += candidates.size();
  const double search_s = 1e-9 * static_cast<double>(monotonic_ns() - search_start_ns);
  stats_.search_s_total += search_s;
  stats_.search_s_max = std::max(stats_.search_s_max, search_s);
  for (const LoopCandidate& c : candidates) {
    const std::int64_t t0 = monotonic_ns();
    try_candidate(c);
    const double verification_s = 1e-9 * static_cast<double>(monotonic_ns() - t0);
    stats_.verification_s_total += verification_s;
    stats_.verification_s_max = std::max(stats_.verification_s_max, verification_s);
  }
  if (unsolved_ == 0) return false;
  const double since_s = 1e-9 * static_cast<double>(stamp_ns - last_optimization_stamp_ns_);
  if (stats_.optimizations > 0 && since_s < config_.optimize_every_s) return false;
  record(optimize(graph_, config_.solver));
  last_optimization_stamp_ns_ = stamp_ns;
  return true;
}

void LoopCloser::try_candidate(const LoopCandidate& c) {
  LoopEvent event{c.query, c.candidate, c.descriptor_distance, "", 0.0, 0.0, 0.0};
  // The candidate's surroundings in its own frame, by the graph.
  // Its storage becomes resident only as the submap's voxels are used (11
  // keyframes fill a small part of it): not 16.8 MB written per candidate.
  VoxelHashMap submap(config_.verification.submap_voxel_m, config_.verification.submap_capacity_voxels,
                      config_.verification.submap_point_spacing_m, VoxelHashMap::Storage::on_first_use);
  const std::size_t w = static_cast<std::size_t>(std::max(0, config_.submap_keyframes));
  const std::size_t first = c.candidate >= w ? c.candidate - w : 0;
  const std::size_t last = std::min(c.candidate + w, c.query - 1);
  const Eigen::Isometry3d candidate_inverse = graph_.nodes[c.candidate].inverse();
  for (std::size_t m = first; m <= last; ++m) {
    if (path_m_[c.query] - path_m_[m] < config_.search.min_path_separation_m) continue;  // not the query's own past
    if (!scans_.read(m, neighbour_)) {
      if (m != c.candidate) continue;  // a neighbour's damaged scan: a smaller submap
      ++stats_.rejected_unreadable;    // the candidate's own: no loop here
      event.outcome = "keyframe_unreadable";
      record_event(std::move(event));
      return;
    }
    add_to_submap(submap, neighbour_, candidate_inverse * graph_.nodes[m]);
  }
  // Guesses: the graph's; Scan Context's yaw at the graph's position, and its
  // other reading when the descriptor finds that one plausible as well.
  const Eigen::Isometry3d graph_guess = candidate_inverse * graph_.nodes[c.query];
  std::vector<Eigen::Isometry3d> guesses{graph_guess};
  if (std::abs(std::remainder(c.yaw_rad - yaw_of(graph_guess), 2.0 * M_PI)) > 0.05)
    guesses.push_back(yawed(graph_guess, c.yaw_rad));
  if (c.alternative_distance <= config_.search.max_descriptor_distance)
    guesses.push_back(yawed(graph_guess, c.alternative_yaw_rad));
  const LoopVerification v = verify_loop(query_points_, submap, guesses, config_.verification);
  stats_.set_aside_readings += static_cast<std::size_t>(v.set_aside);
  event.inlier_ratio = v.registration.inlier_ratio;
  event.rmse_m = v.registration.rmse_m;
  event.conditioning = v.registration.weakest_eigenvalue;
  if (v.verdict != LoopVerdict::accepted && v.verdict != LoopVerdict::partial) {
    ++stats_.rejected_verification;
    event.outcome = std::string(to_string(v.verdict));
    record_event(std::move(event));
    return;
  }
  ++stats_.verified;
  if (v.verdict == LoopVerdict::partial) ++stats_.partial;
  const LoopConstraint loop{c.candidate, c.query, v.relative, config_.verification.covariance_sigma_m, v.free_axis};
  GuardDecision decision = GuardDecision::waiting;
  const std::vector<LoopConstraint> newly = guard_.submit(loop, graph_.nodes, variance_, decision);
  const std::string kind = v.verdict == LoopVerdict::partial ? "_partial" : "";
  event.outcome = (decision == GuardDecision::accepted  ? "accepted"
                   : decision == GuardDecision::waiting ? "waiting"
                                                        : "inconsistent") +
                  kind;
  if (decision == GuardDecision::rejected) ++stats_.rejected_inconsistent;
  record_event(std::move(event));
  // A waiting loop keeps its information until a witness lets it in.
  if (decision == GuardDecision::waiting) information_.push_back({c.query, c.candidate, v.information});
  for (const LoopConstraint& l : newly) {
    Matrix6d information = v.information;  // this candidate's loop
    const auto waited = std::find_if(information_.begin(), information_.end(), [&](const PendingInformation& p) {
      return p.query == l.to && p.candidate == l.from;
    });
    if (waited != information_.end()) {  // a waiting one it confirmed
      information = waited->information;
      information_.erase(waited);
    }
    graph_.edges.push_back({l.from, l.to, l.measurement, information, EdgeKind::loop});
    ++stats_.accepted;
    ++unsolved_;
  }
}

void LoopCloser::record_event(LoopEvent event) {
  ++outcomes_[event.outcome];
  if (events_.size() < config_.events_kept) events_.push_back(std::move(event));
}

void LoopCloser::record(const PoseGraphSolution& solution) {
  unsolved_ = 0;
  ++stats_.optimizations;
  stats_.last_optimization_s = solution.time_s;
  stats_.optimization_s_total += solution.time_s;
  stats_.last_optimization_iterations = solution.iterations;
  stats_.optimization_iterations_total += static_cast<std::size_t>(solution.iterations);
}

Eigen::Isometry3d LoopCloser::correction() const {
  if (graph_.nodes.empty()) return Eigen::Isometry3d::Identity();
  return graph_.nodes.back() * odometry_.back().inverse();
}

void LoopCloser::refine() {
  if (graph_.loop_count() == 0) return;
  PoseGraphSolverConfig batch = config_.solver;
  batch.max_iterations = std::max(batch.max_iterations, 200);
  batch.max_time_s = std::max(batch.max_time_s, 10.0);
  const PoseGraphSolution solution = optimize(graph_, batch);
  record(solution);
}

}  // namespace adit::slam
