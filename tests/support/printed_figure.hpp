#pragma once
// Reading a figure a command printed: the number after `key` on the line that
// contains `line`, NaN when either is absent (so that a test's comparison
// fails with the output in its message).

#include <cmath>
#include <string>

namespace adit::test {

inline double printed_figure(const std::string& output, const std::string& line, const std::string& key) {
  const std::size_t at = output.find(line);
  if (at == std::string::npos) return std::nan("");
  const std::size_t end = output.find('\n', at);
  const std::size_t k = output.find(key, at);
  if (k == std::string::npos || k > end) return std::nan("");
  return std::stod(output.substr(k + key.size()));
}

}  // namespace adit::test
