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

bool correction_may_move(const CorrectionTrack& a, const CorrectionTrack* b, const Eigen::AlignedBox3d& box,
                         double newest_s, double min_move_m) {
  if (a.empty()) return true;
  const double limit2 = 0.25 * min_move_m * min_move_m;  // (min_move_m / 2)²
  const auto moves_at = [&](std::int64_t ns) {
    const Eigen::Isometry3d ca = a.at(ns);
    const Eigen::Isometry3d cb = b == nullptr ? Eigen::Isometry3d::Identity() : b->at(ns);
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d p = box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
      if ((cb * p - ca * p).squaredNorm() > limit2) return true;
    }
    return false;
  };
  const std::vector<std::int64_t>& stamps = a.stamps_ns();
  for (std::size_t k = 0; k < stamps.size(); ++k) {
    if (moves_at(stamps[k])) return true;
    if (k + 1 < stamps.size() && moves_at(stamps[k] + (stamps[k + 1] - stamps[k]) / 2)) return true;
  }
  const auto newest_ns = static_cast<std::int64_t>(std::llround(newest_s * 1e9));
  if (b == nullptr || newest_ns <= stamps.back()) return false;
  std::int64_t previous = stamps.back();
  const std::vector<std::int64_t>& later = b->stamps_ns();
  for (auto it = std::upper_bound(later.begin(), later.end(), previous); it != later.end() && *it < newest_ns; ++it) {
    if (moves_at(previous + (*it - previous) / 2) || moves_at(*it)) return true;
    previous = *it;
  }
  return moves_at(previous + (newest_ns - previous) / 2) || moves_at(newest_ns);
}

CorrectionTrack CorrectionTrack::merged_with(const CorrectionTrack& other) const {
  if (other.stamps_.empty()) return *this;
  if (stamps_.empty()) return other;
  // Each keyframe of the union, by stamp: its index in this slice and in the
  // other (kNone where it is not).
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  struct Entry {
    std::size_t mine = kNone;
    std::size_t theirs = kNone;
  };
  std::vector<Entry> order;
  order.reserve(stamps_.size() + other.stamps_.size());
  std::size_t i = 0, j = 0;
  while (i < stamps_.size() || j < other.stamps_.size()) {
    const bool take_mine = j == other.stamps_.size() || (i < stamps_.size() && stamps_[i] <= other.stamps_[j]);
    const bool take_theirs = i == stamps_.size() || (j < other.stamps_.size() && other.stamps_[j] <= stamps_[i]);
    order.push_back({take_mine ? i++ : kNone, take_theirs ? j++ : kNone});
  }
  CorrectionTrack merged;
  for (std::size_t n = 0; n < order.size(); ++n) {
    const Entry e = order[n];
    const CorrectionTrack& t = e.mine != kNone ? *this : other;
    const std::size_t k = e.mine != kNone ? e.mine : e.theirs;
    merged.stamps_.push_back(t.stamps_[k]);
    merged.positions_.push_back(t.positions_[k]);
    merged.corrections_.push_back(t.corrections_[k]);
    if (n + 1 == order.size()) break;
    // A pair next to each other in either slice keeps that slice's step (the
    // same bits at its samples' times); no sample of either falls between
    // any other pair.
    const Entry next = order[n + 1];
    if (e.mine != kNone && next.mine == e.mine + 1) {
      merged.steps_.push_back(steps_[e.mine]);
    } else if (e.theirs != kNone && next.theirs == e.theirs + 1) {
      merged.steps_.push_back(other.steps_[e.theirs]);
    } else {
      const CorrectionTrack& u = next.mine != kNone ? *this : other;
      const std::size_t m = next.mine != kNone ? next.mine : next.theirs;
      merged.steps_.push_back(log_se3(t.corrections_[k].inverse() * u.corrections_[m]));
    }
  }
  return merged;
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
