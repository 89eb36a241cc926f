#include "adit/slam/session_join.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace adit::slam {
namespace {

bool agree(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, const SessionJoinConfig& config) {
  const Eigen::Isometry3d d = a.inverse() * b;
  return d.translation().norm() <= config.agree_m && Eigen::AngleAxisd(d.linear()).angle() <= config.agree_rad;
}

// Path length at each pose.
std::vector<double> path_lengths(const Trajectory& trajectory) {
  std::vector<double> s(trajectory.size(), 0.0);
  for (std::size_t i = 1; i < trajectory.size(); ++i)
    s[i] = s[i - 1] + (trajectory.poses[i].translation() - trajectory.poses[i - 1].translation()).norm();
  return s;
}

// The poses to try: one every place_spacing_m of path (wider when the path
// would give more than max_places), the first at the start.
std::vector<std::size_t> places_along(const std::vector<double>& s, const SessionJoinConfig& config) {
  std::vector<std::size_t> out;
  if (s.empty()) return out;
  double spacing = config.place_spacing_m;
  if (config.max_places > 1) spacing = std::max(spacing, s.back() / static_cast<double>(config.max_places - 1));
  double next = 0.0;
  for (std::size_t i = 0; i < s.size() && static_cast<int>(out.size()) < config.max_places; ++i)
    if (s[i] >= next) {
      out.push_back(i);
      next = s[i] + spacing;
    }
  return out;
}

// What a sensor at `origin` sees of the map: points within the radius, relative to the origin.
void cloud_round(std::span<const Eigen::Vector3f> points, const Eigen::Vector3f& origin, const SessionJoinConfig& config,
                 std::vector<Eigen::Vector3f>& cloud) {
  cloud.clear();
  const float r2 = config.cloud_radius_m * config.cloud_radius_m;
  for (const Eigen::Vector3f& p : points) {
    const Eigen::Vector3f d = p - origin;
    if (d.head<2>().squaredNorm() <= r2 && std::abs(d.z()) <= config.cloud_height_m) cloud.push_back(d);
  }
}

}  // namespace

SessionJoinResult join_session(const PriorMap& stored, const VoxelHashMap& index, std::span<const Eigen::Vector3f> new_points,
                               const Trajectory& new_trajectory, const SessionJoinConfig& config) {
  SessionJoinResult result;
  if (new_trajectory.empty() || new_points.empty()) {
    result.failure = "the session to join has no map or no trajectory";
    return result;
  }
  const std::vector<double> s = path_lengths(new_trajectory);
  std::vector<Eigen::Isometry3d> transforms;  // stored_from_new of each place that localised
  std::vector<std::size_t> localised;         // their indices in result.places
  std::vector<Eigen::Vector3f> cloud;
  cloud.reserve(new_points.size());
  for (const std::size_t i : places_along(s, config)) {
    if (config.cancel != nullptr && config.cancel->load()) {
      result.failure = "cancelled";
      return result;
    }
    const Eigen::Vector3f origin =
        (new_trajectory.poses[i].translation() + Eigen::Vector3d(0.0, 0.0, config.sensor_height_m)).cast<float>();
    cloud_round(new_points, origin, config, cloud);
    JoinPlace place;
    place.path_m = s[i];
    place.result = localise(cloud, stored, index, std::nullopt, config.localisation);
    if (place.result.success) {
      transforms.push_back(place.result.pose * Eigen::Translation3d(-origin.cast<double>()));
      localised.push_back(result.places.size());
    }
    result.places.push_back(std::move(place));
  }
  result.places_tried = static_cast<int>(result.places.size());
  result.places_localised = static_cast<int>(localised.size());
  if (localised.empty()) {
    result.failure = fmt::format("none of {} places along its path localised in the stored map", result.places_tried);
    return result;
  }
  // The largest group of places agreeing with one of them (the best overlap
  // breaks ties), and the largest group among the places outside it.
  const auto group_of = [&](std::size_t a, const std::vector<bool>& allowed) {
    std::vector<std::size_t> members;
    for (std::size_t b = 0; b < localised.size(); ++b)
      if (allowed[b] && agree(transforms[a], transforms[b], config)) members.push_back(b);
    return members;
  };
  const auto largest = [&](const std::vector<bool>& allowed) {
    std::vector<std::size_t> best;
    double best_overlap = -1.0;
    for (std::size_t a = 0; a < localised.size(); ++a) {
      if (!allowed[a]) continue;
      std::vector<std::size_t> members = group_of(a, allowed);
      const double overlap = result.places[localised[a]].result.overlap;
      if (members.size() > best.size() || (members.size() == best.size() && overlap > best_overlap)) {
        best = std::move(members);
        best_overlap = overlap;
      }
    }
    return best;
  };
  std::vector<bool> allowed(localised.size(), true);
  const std::vector<std::size_t> group = largest(allowed);
  for (const std::size_t b : group) allowed[b] = false;
  const std::vector<std::size_t> rival = largest(allowed);
  double first = -1.0, last = -1.0;
  for (const std::size_t b : group) {
    JoinPlace& place = result.places[localised[b]];
    place.agrees = true;
    if (first < 0.0) first = place.path_m;
    last = place.path_m;
    if (place.result.overlap > result.overlap) {
      result.overlap = place.result.overlap;
      result.stored_from_new = transforms[b];
    }
  }
  result.places_agreeing = static_cast<int>(group.size());
  result.first_agreeing_path_m = first;
  const int disagreeing = result.places_localised - result.places_agreeing;
  if (rival.size() >= 2) {
    const Eigen::Isometry3d d = result.stored_from_new.inverse() * transforms[rival.front()];
    result.failure = fmt::format(
        "ambiguous: {} places agree on one transform and {} on another, {:.2f} m and {:.1f} deg apart",
        group.size(), rival.size(), d.translation().norm(), Eigen::AngleAxisd(d.linear()).angle() * 180.0 / M_PI);
    return result;
  }
  if (disagreeing >= result.places_agreeing) {
    result.failure = fmt::format("ambiguous: {} places localised, only {} of them on one transform",
                                 result.places_localised, result.places_agreeing);
    return result;
  }
  if (last - first < config.confirm_apart_m) {
    result.failure = fmt::format(
        "not confirmed: {} place(s) localised, between {:.0f} m and {:.0f} m of its path; a join needs two that agree "
        "at least {:.0f} m apart",
        result.places_agreeing, first, last, config.confirm_apart_m);
    return result;
  }
  result.success = true;
  return result;
}

}  // namespace adit::slam
