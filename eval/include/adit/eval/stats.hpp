#pragma once
// Summary statistics of an error series, as trajectory-evaluation tools
// report them (population standard deviation, median of the sorted values).

#include <cstddef>
#include <span>

namespace adit::eval {

struct Stats {
  std::size_t count = 0;
  double rmse = 0.0;  // sqrt(sse / n)
  double mean = 0.0;
  double median = 0.0;  // mean of the two middle values when n is even
  double std = 0.0;     // sqrt(sum (e - mean)^2 / n)
  double min = 0.0;
  double max = 0.0;
  double sse = 0.0;  // sum e^2
};

// All fields zero for an empty series.
Stats compute_stats(std::span<const double> values);

}  // namespace adit::eval
