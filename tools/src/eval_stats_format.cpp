// Stats as a table row and as JSON, shared by the eval runners.

#include <fmt/format.h>

#include "eval_commands.hpp"

namespace adit::tools {

nlohmann::json stats_json(const eval::Stats& s) {
  return {{"count", s.count}, {"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median},
          {"std", s.std},     {"min", s.min},   {"max", s.max},   {"sse", s.sse}};
}

std::string stats_header() {
  return fmt::format("{:<28} {:>6} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>12}\n", "metric", "n", "rmse", "mean",
                     "median", "std", "min", "max", "sse");
}

std::string stats_row(const std::string& name, const eval::Stats& s) {
  return fmt::format("{:<28} {:>6} {:>10.6f} {:>10.6f} {:>10.6f} {:>10.6f} {:>10.6f} {:>10.6f} {:>12.6g}\n", name,
                     s.count, s.rmse, s.mean, s.median, s.std, s.min, s.max, s.sse);
}

}  // namespace adit::tools
