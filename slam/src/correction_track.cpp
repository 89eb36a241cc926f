// The map→odometry correction through time (correction_track.hpp).
#include "adit/slam/correction_track.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "adit/slam/trajectory_interpolate.hpp"

namespace adit::slam {

CorrectionTrack::CorrectionTrack(std::span<const std::int64_t> stamps_ns, std::span<const Eigen::Isometry3d> graph,
                                 std::span<const Eigen::Isometry3d> odometry) {
  const std::size_t n = std::min({stamps_ns.size(), graph.size(), odometry.size()});
  stamps_.assign(stamps_ns.begin(), stamps_ns.begin() + static_cast<std::ptrdiff_t>(n));
  corrections_.reserve(n);
  positions_.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    corrections_.push_back(graph[k] * odometry[k].inverse());
    positions_.push_back(graph[k].translation());
  }
  steps_.reserve(n);
  for (std::size_t k = 0; k + 1 < n; ++k) steps_.push_back(log_se3(corrections_[k].inverse() * corrections_[k + 1]));
}

Eigen::Isometry3d CorrectionTrack::at(std::int64_t stamp_ns) const {
  if (stamps_.empty()) return Eigen::Isometry3d::Identity();
  const auto it = std::upper_bound(stamps_.begin(), stamps_.end(), stamp_ns);
  if (it == stamps_.begin()) return corrections_.front();
  if (it == stamps_.end()) return corrections_.back();
  const auto b = static_cast<std::size_t>(it - stamps_.begin());
  const std::size_t a = b - 1;
  const double s = static_cast<double>(stamp_ns - stamps_[a]) / static_cast<double>(stamps_[b] - stamps_[a]);
  return corrections_[a] * exp_se3(s * steps_[a]);
}

namespace {

std::int64_t stamp_of(const MapSample& s) { return static_cast<std::int64_t>(std::llround(s.time_s * 1e9)); }

}  // namespace

void correct_samples(std::span<const MapSample> in, const CorrectionTrack* track, const Eigen::Isometry3d& placed_by,
                     std::vector<MapSample>& out) {
  out.assign(in.begin(), in.end());
  if (track == nullptr || track->empty()) {
    for (MapSample& s : out) s.position = (placed_by * s.position.cast<double>()).cast<float>();
    return;
  }
  double time = std::numeric_limits<double>::quiet_NaN();
  Eigen::Isometry3d c = placed_by;
  for (MapSample& s : out) {
    if (s.time_s != time) {
      time = s.time_s;
      c = placed_by * track->at(stamp_of(s));
    }
    s.position = (c * s.position.cast<double>()).cast<float>();
  }
}

bool correction_moves(std::span<const MapSample> samples, const CorrectionTrack* a, const CorrectionTrack* b,
                      double min_move_m) {
  if (a == b) return false;
  const auto at = [](const CorrectionTrack* t, std::int64_t ns) {
    return t == nullptr ? Eigen::Isometry3d::Identity() : t->at(ns);
  };
  double time = std::numeric_limits<double>::quiet_NaN();
  Eigen::Isometry3d ca = Eigen::Isometry3d::Identity(), cb = ca;
  const double min2 = min_move_m * min_move_m;
  for (const MapSample& s : samples) {
    if (s.time_s != time) {
      time = s.time_s;
      ca = at(a, stamp_of(s));
      cb = at(b, stamp_of(s));
    }
    const Eigen::Vector3d p = s.position.cast<double>();
    if ((cb * p - ca * p).squaredNorm() > min2) return true;
  }
  return false;
}

CorrectionTrack CorrectionTrack::slice_for(std::span<const MapSample> samples) const {
  CorrectionTrack slice;
  if (stamps_.empty()) return slice;
  // at(t) reads the keyframes a = b − 1 and b, b the first stamp after t, or
  // the first or last alone beyond the ends: those are kept.
  std::vector<std::size_t> kept;
  double time = std::numeric_limits<double>::quiet_NaN();
  for (const MapSample& s : samples) {
    if (s.time_s == time) continue;
    time = s.time_s;
    const auto it = std::upper_bound(stamps_.begin(), stamps_.end(), stamp_of(s));
    const auto b = static_cast<std::size_t>(it - stamps_.begin());
    if (b == 0) {
      kept.push_back(0);
    } else if (b == stamps_.size()) {
      kept.push_back(b - 1);
    } else {
      kept.push_back(b - 1);
      kept.push_back(b);
    }
  }
  std::sort(kept.begin(), kept.end());
  kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const std::size_t k = kept[i];
    slice.stamps_.push_back(stamps_[k]);
    slice.positions_.push_back(positions_[k]);
    slice.corrections_.push_back(corrections_[k]);
    if (i + 1 == kept.size()) break;
    // A kept pair's own step (the same bits); across a gap no sample's time falls.
    const std::size_t next = kept[i + 1];
    slice.steps_.push_back(next == k + 1 ? steps_[k] : log_se3(corrections_[k].inverse() * corrections_[next]));
  }
  return slice;
}

CorrectionTrack retargeted(const CorrectionTrack& track, const Trajectory& built_at, const Trajectory& poses) {
  if (track.empty() || built_at.empty()) return {};
  std::vector<std::int64_t> stamps;
  std::vector<Eigen::Isometry3d> graph;
  std::vector<Eigen::Isometry3d> odometry;
  stamps.reserve(poses.size());
  graph.reserve(poses.size());
  odometry.reserve(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const auto stamp_ns = static_cast<std::int64_t>(std::llround(poses.stamps[i] * 1e9));
    if (!stamps.empty() && stamp_ns <= stamps.back()) continue;  // a repeated stamp: the first pose stands
    const double t = std::clamp(poses.stamps[i], built_at.stamps.front(), built_at.stamps.back());
    stamps.push_back(stamp_ns);
    graph.push_back(track.at(stamp_ns) * interpolate_pose(built_at, t).value_or(built_at.poses.front()));
    odometry.push_back(poses.poses[i]);
  }
  return CorrectionTrack(stamps, graph, odometry);
}

double CorrectionTrack::max_translation_m() const {
  double m = 0.0;
  for (const Eigen::Isometry3d& c : corrections_) m = std::max(m, c.translation().norm());
  return m;
}

double CorrectionTrack::max_rotation_rad() const {
  double m = 0.0;
  for (const Eigen::Isometry3d& c : corrections_) m = std::max(m, Eigen::AngleAxisd(c.linear()).angle());
  return m;
}

}  // namespace adit::slam
