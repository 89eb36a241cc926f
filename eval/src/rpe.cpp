#include "adit/eval/rpe.hpp"

#include <algorithm>
#include <cmath>

#include "adit/eval/pose_error.hpp"

namespace adit::eval {
namespace {

// For every i, the j > i whose values[j] - values[i] is closest to delta,
// kept when within tolerance. `values` is non-decreasing (path or time).
std::vector<IndexPair> all_pairs_by_value(std::span<const double> values, double delta, double tolerance) {
  std::vector<IndexPair> pairs;
  pairs.reserve(values.size());
  for (std::size_t i = 0; i + 1 < values.size(); ++i) {
    const double target = values[i] + delta;
    const auto first = values.begin() + static_cast<std::ptrdiff_t>(i + 1);
    const auto hit = std::lower_bound(first, values.end(), target);
    std::size_t best = values.size();
    double best_residual = 0.0;
    // The closest value is at the lower bound or just before it; among equal
    // values (no motion) the earliest wins, as in the linear scan.
    const auto below = hit == first ? hit : std::lower_bound(first, hit, *(hit - 1));
    for (auto it : {below, hit}) {
      if (it == hit && it == values.end()) continue;
      if (it == below && below == hit) continue;
      const double residual = std::abs(*it - values[i] - delta);  // as the linear scan computes it
      if (best == values.size() || residual < best_residual) {
        best = static_cast<std::size_t>(it - values.begin());
        best_residual = residual;
      }
    }
    if (best < values.size() && best_residual <= tolerance) pairs.emplace_back(i, best);
  }
  return pairs;
}

std::vector<IndexPair> chain(const std::vector<std::size_t>& ids) {
  std::vector<IndexPair> pairs;
  for (std::size_t k = 1; k < ids.size(); ++k) pairs.emplace_back(ids[k - 1], ids[k]);
  return pairs;
}

}  // namespace

std::optional<DeltaUnit> parse_delta_unit(std::string_view name) {
  if (name == "frames" || name == "f") return DeltaUnit::frames;
  if (name == "m" || name == "metres" || name == "meters") return DeltaUnit::metres;
  if (name == "s" || name == "seconds") return DeltaUnit::seconds;
  return std::nullopt;
}

std::string_view delta_unit_name(DeltaUnit unit) {
  switch (unit) {
    case DeltaUnit::frames: return "frames";
    case DeltaUnit::metres: return "m";
    case DeltaUnit::seconds: return "s";
  }
  return "?";
}

std::vector<IndexPair> rpe_pairs(std::span<const double> distances, std::span<const double> stamps,
                                 const RpeSettings& settings) {
  const double delta = settings.delta;
  const std::size_t n = distances.size();
  std::vector<IndexPair> pairs;
  if (!(delta > 0.0) || n < 2) return pairs;

  if (settings.unit == DeltaUnit::frames) {
    const auto step = static_cast<std::size_t>(std::max(1.0, std::round(delta)));
    if (settings.all_pairs) {
      for (std::size_t i = 0; i + step < n; ++i) pairs.emplace_back(i, i + step);
      return pairs;
    }
    for (std::size_t i = 0; i + step < n; i += step) pairs.emplace_back(i, i + step);
    return pairs;
  }

  const std::span<const double> values = settings.unit == DeltaUnit::metres ? distances : stamps;
  if (settings.all_pairs) return all_pairs_by_value(values, delta, settings.relative_tolerance * delta);

  std::vector<std::size_t> ids;
  if (settings.unit == DeltaUnit::seconds) ids.push_back(0);
  double since = settings.unit == DeltaUnit::seconds ? values[0] : 0.0;
  for (std::size_t i = 1; i < values.size(); ++i) {
    if (values[i] - since >= delta) {
      ids.push_back(i);
      since = values[i];
    }
  }
  return chain(ids);
}

std::vector<IndexPair> rpe_pairs_all_naive(std::span<const double> values, double delta, double tolerance) {
  std::vector<IndexPair> pairs;
  for (std::size_t i = 0; i + 1 < values.size(); ++i) {
    std::size_t best = values.size();
    double best_residual = 0.0;
    for (std::size_t j = i + 1; j < values.size(); ++j) {
      const double residual = std::abs(values[j] - values[i] - delta);
      if (best == values.size() || residual < best_residual) {
        best = j;
        best_residual = residual;
      }
    }
    if (best < values.size() && best_residual <= tolerance) pairs.emplace_back(i, best);
  }
  return pairs;
}

PoseErrors relative_pose_errors(std::span<const slam::Pose> ref, std::span<const slam::Pose> est,
                                std::span<const IndexPair> pairs) {
  PoseErrors out;
  out.translation.reserve(pairs.size());
  out.rotation_deg.reserve(pairs.size());
  for (const auto& [i, j] : pairs) {
    const slam::Pose ref_delta = ref[i].inverse() * ref[j];
    const slam::Pose est_delta = est[i].inverse() * est[j];
    const slam::Pose error = ref_delta.inverse() * est_delta;
    out.translation.push_back(error.translation().norm());
    out.rotation_deg.push_back(rad_to_deg(rotation_angle(error.linear())));
  }
  return out;
}

}  // namespace adit::eval
