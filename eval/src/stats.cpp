#include "adit/eval/stats.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace adit::eval {

Stats compute_stats(std::span<const double> values) {
  Stats s;
  s.count = values.size();
  if (values.empty()) return s;
  const double n = static_cast<double>(values.size());
  double sum = 0.0;
  s.min = values.front();
  s.max = values.front();
  for (const double v : values) {
    sum += v;
    s.sse += v * v;
    s.min = std::min(s.min, v);
    s.max = std::max(s.max, v);
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(s.sse / n);
  double var = 0.0;
  for (const double v : values) var += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(var / n);

  std::vector<double> sorted(values.begin(), values.end());
  const std::size_t mid = sorted.size() / 2;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(mid), sorted.end());
  s.median = sorted[mid];
  if (sorted.size() % 2 == 0) {
    const double below = *std::max_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(mid));
    s.median = 0.5 * (s.median + below);
  }
  return s;
}

}  // namespace adit::eval
