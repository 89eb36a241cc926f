#include "text_fields.hpp"

#include <charconv>
#include <cmath>

namespace adit::eval::detail {
namespace {
bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}
}  // namespace

void split_fields(std::string_view line, std::string_view separators, std::vector<std::string_view>& out) {
  out.clear();
  line = trim(line);
  const bool whitespace_only = separators.find_first_not_of(" \t") == std::string_view::npos;
  std::size_t start = 0;
  while (start <= line.size()) {
    std::size_t end = line.find_first_of(separators, start);
    if (end == std::string_view::npos) end = line.size();
    const std::string_view field = trim(line.substr(start, end - start));
    // With whitespace separators, runs of blanks are one separator.
    if (!(whitespace_only && field.empty())) out.push_back(field);
    start = end + 1;
  }
  if (line.empty()) out.clear();
}

std::optional<double> parse_double(std::string_view field) {
  if (!field.empty() && field.front() == '+') field.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
  if (ec != std::errc{} || end != field.data() + field.size() || field.empty() || !std::isfinite(value))
    return std::nullopt;
  return value;
}

std::optional<std::int64_t> parse_int64(std::string_view field) {
  if (!field.empty() && field.front() == '+') field.remove_prefix(1);
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
  if (ec != std::errc{} || end != field.data() + field.size() || field.empty()) return std::nullopt;
  return value;
}

bool is_comment_or_blank(std::string_view line) {
  line = trim(line);
  return line.empty() || line.front() == '#';
}

}  // namespace adit::eval::detail
