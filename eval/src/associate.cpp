#include "adit/eval/associate.hpp"

#include <cmath>

namespace adit::eval {
namespace {

// For each stamp of `sparse` (shifted), the nearest stamp of `dense`: two
// pointers, both lists sorted. When two sparse stamps pick the same dense one
// the closer keeps it. Returns (index in sparse, index in dense).
std::vector<IndexPair> nearest(std::span<const double> sparse, std::span<const double> dense, double sparse_shift,
                               double max_difference) {
  std::vector<IndexPair> out;
  if (dense.empty()) return out;
  out.reserve(sparse.size());
  const auto gap = [&](std::size_t i, std::size_t j) { return std::abs(dense[j] - (sparse[i] + sparse_shift)); };
  std::size_t j = 0;
  for (std::size_t i = 0; i < sparse.size(); ++i) {
    while (j + 1 < dense.size() && gap(i, j + 1) <= gap(i, j)) ++j;
    if (gap(i, j) > max_difference) continue;
    if (!out.empty() && out.back().second == j) {
      if (gap(i, j) < gap(out.back().first, j)) out.back().first = i;
      continue;
    }
    out.emplace_back(i, j);
  }
  return out;
}

}  // namespace

std::vector<IndexPair> associate(std::span<const double> ref_stamps, std::span<const double> est_stamps,
                                 double max_difference, double offset) {
  if (ref_stamps.size() >= est_stamps.size()) {
    std::vector<IndexPair> pairs = nearest(est_stamps, ref_stamps, offset, max_difference);
    for (auto& [a, b] : pairs) std::swap(a, b);
    return pairs;
  }
  return nearest(ref_stamps, est_stamps, -offset, max_difference);
}

Associated associate(const slam::Trajectory& ref, const slam::Trajectory& est, double max_difference, double offset) {
  Associated out;
  if (ref.timed && est.timed) {
    out.pairs = associate(ref.stamps, est.stamps, max_difference, offset);
  } else if (ref.size() == est.size()) {
    for (std::size_t i = 0; i < ref.size(); ++i) out.pairs.emplace_back(i, i);
  }
  out.stamps.reserve(out.pairs.size());
  out.ref.reserve(out.pairs.size());
  out.est.reserve(out.pairs.size());
  for (const auto& [i, j] : out.pairs) {
    out.stamps.push_back(ref.stamps[i]);
    out.ref.push_back(ref.poses[i]);
    out.est.push_back(est.poses[j]);
  }
  return out;
}

}  // namespace adit::eval
