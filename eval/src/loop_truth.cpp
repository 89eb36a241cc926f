#include "adit/eval/loop_truth.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/eval/interpolate.hpp"
#include "adit/eval/path.hpp"

namespace adit::eval {

std::optional<Eigen::Vector3d> free_axis(const slam::Matrix6d& information) {
  const Eigen::SelfAdjointEigenSolver<slam::Matrix6d> eig(0.5 * (information + information.transpose()));
  const double largest = eig.eigenvalues()(5);
  if (!(largest > 0.0) || eig.eigenvalues()(0) > 1e-9 * largest) return std::nullopt;
  const Eigen::Matrix<double, 6, 1> w = eig.eigenvectors().col(0);
  if (w.head<3>().norm() <= 0.5) return std::nullopt;  // a rotation left free: not a partial loop's axis
  return Eigen::Vector3d(w.head<3>().normalized());
}

KeyframeTruth keyframe_truth(const slam::Trajectory& truth, std::span<const double> stamps,
                             const std::string& truth_name) {
  const std::vector<double> along = path_distances(truth.poses);
  KeyframeTruth out;
  out.poses.reserve(stamps.size());
  out.path_m.reserve(stamps.size());
  for (std::size_t k = 0; k < stamps.size(); ++k) {
    const std::optional<slam::Pose> pose = interpolate_pose(truth, stamps[k]);
    if (!pose)
      throw InputError(truth_name, "",
                       fmt::format("keyframe {} at {:.6f} s lies outside the truth ({} poses{})", k, stamps[k],
                                   truth.size(),
                                   truth.empty() ? std::string()
                                                 : fmt::format(", {:.6f} to {:.6f} s", truth.stamps.front(),
                                                               truth.stamps.back())));
    // The true path's length at the stamp, linear between the truth's samples.
    const auto after = std::lower_bound(truth.stamps.begin(), truth.stamps.end(), stamps[k]);
    const auto j = static_cast<std::size_t>(after - truth.stamps.begin());
    double path = along[j];
    if (j > 0 && *after != stamps[k]) {
      const double f = (stamps[k] - truth.stamps[j - 1]) / (truth.stamps[j] - truth.stamps[j - 1]);
      path = along[j - 1] + f * (along[j] - along[j - 1]);
    }
    out.poses.push_back(*pose);
    out.path_m.push_back(path);
  }
  return out;
}

namespace {

double distance(const slam::Pose& a, const slam::Pose& b) { return (a.translation() - b.translation()).norm(); }

}  // namespace

LoopTruthReport evaluate_loops(const KeyframeTruth& truth, std::span<const LoopEdgeRecord> loops,
                               const LoopTruthConfig& config, const std::string& loops_name) {
  LoopTruthReport r;
  const std::size_t n = truth.poses.size();
  r.keyframes = n;
  // Revisit keyframes: an earlier keyframe close by, far back along the path.
  for (std::size_t q = 0; q < n; ++q) {
    for (std::size_t c = 0; c < q; ++c) {
      if (truth.path_m[q] - truth.path_m[c] < config.min_path_m) break;  // path grows with c
      if (distance(truth.poses[q], truth.poses[c]) <= config.revisit_m) {
        r.revisit_keyframes.push_back(q);
        break;
      }
    }
  }
  for (const std::size_t q : r.revisit_keyframes) {
    if (r.revisit_stretches.empty() || q != r.revisit_stretches.back().last + 1)
      r.revisit_stretches.push_back({q, q});
    else
      r.revisit_stretches.back().last = q;
  }
  // Each accepted loop against the truth.
  std::vector<double> errors_m, errors_deg;
  std::vector<std::size_t> true_queries;
  for (const LoopEdgeRecord& loop : loops) {
    if (loop.from >= n || loop.to >= n)
      throw InputError(loops_name, "edges",
                       fmt::format("loop {} -> {} names a keyframe beyond the {} keyframes", loop.from, loop.to, n));
    LoopCheck c;
    c.loop = loop;
    const slam::Pose& a = truth.poses[loop.from];
    const slam::Pose& b = truth.poses[loop.to];
    c.truth_distance_m = distance(a, b);
    c.truth_path_m = std::abs(truth.path_m[loop.to] - truth.path_m[loop.from]);
    const slam::Pose relative = a.inverse() * b;
    const Eigen::Vector3d d = relative.translation() - loop.measurement.translation();  // from's frame
    c.error_m = d.norm();
    c.error_judged_m = c.error_m;
    if (const std::optional<Eigen::Vector3d> axis = free_axis(loop.information)) {
      c.partial = true;
      c.error_judged_m = (d - d.dot(*axis) * *axis).norm();
    }
    c.error_deg = Eigen::AngleAxisd(loop.measurement.linear().transpose() * relative.linear()).angle() * 180.0 / M_PI;
    c.is_false = c.truth_distance_m > config.false_beyond_m || c.error_judged_m > config.max_error_m ||
                 c.error_deg > config.max_error_deg;
    if (c.is_false) {
      ++r.false_loops;
    } else {
      errors_m.push_back(c.error_judged_m);
      errors_deg.push_back(c.error_deg);
      true_queries.push_back(std::max(loop.from, loop.to));
    }
    r.loops.push_back(c);
  }
  r.error_m = compute_stats(errors_m);
  r.error_deg = compute_stats(errors_deg);
  if (!loops.empty())
    r.precision = static_cast<double>(loops.size() - r.false_loops) / static_cast<double>(loops.size());
  // Recall: a true loop's query within ±window keyframes.
  std::sort(true_queries.begin(), true_queries.end());
  std::size_t stretch = 0;
  bool stretch_recalled = false;
  for (const std::size_t q : r.revisit_keyframes) {
    while (stretch < r.revisit_stretches.size() && r.revisit_stretches[stretch].last < q) {
      ++stretch;
      stretch_recalled = false;
    }
    const std::size_t lo = q >= config.window ? q - config.window : 0;
    const auto it = std::lower_bound(true_queries.begin(), true_queries.end(), lo);
    if (it == true_queries.end() || *it > q + config.window) continue;
    ++r.recalled_keyframes;
    if (!stretch_recalled) {
      ++r.recalled_stretches;
      stretch_recalled = true;
    }
  }
  if (!r.revisit_keyframes.empty())
    r.recall = static_cast<double>(r.recalled_keyframes) / static_cast<double>(r.revisit_keyframes.size());
  return r;
}

}  // namespace adit::eval
