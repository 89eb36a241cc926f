#pragma once
// The association tests' reference: the index of the stamp nearest to t, by brute force.

#include <cmath>
#include <cstddef>
#include <vector>

namespace adit::eval {

inline std::size_t brute_nearest(const std::vector<double>& stamps, double t) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < stamps.size(); ++i)
    if (std::abs(stamps[i] - t) < std::abs(stamps[best] - t)) best = i;
  return best;
}

}  // namespace adit::eval
