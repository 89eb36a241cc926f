#pragma once
// The q-quantile (0..1) of a series by nearest rank, as the benchmarks and
// the session summary report medians and p99s; 0 for an empty series.

#include <algorithm>
#include <cstddef>
#include <vector>

namespace adit {

inline double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1) + 0.5);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

}  // namespace adit
