// HINT's arguments (localise_hint.hpp).
#include "adit/protocol/localise_hint.hpp"

#include <charconv>
#include <cmath>
#include <string_view>

#include <fmt/format.h>

namespace adit::protocol {
namespace {

// A finite number spelled whole (no trailing text).
std::optional<double> number(std::string_view text) {
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

}  // namespace

std::optional<LocaliseHint> parse_localise_hint(const std::vector<std::string>& args, std::string& error) {
  LocaliseHint hint;
  bool has_x = false;
  bool has_y = false;
  for (const std::string& arg : args) {
    const std::size_t eq = arg.find('=');
    if (eq == std::string::npos) {
      error = fmt::format("argument '{}' is not key=value", arg);
      return std::nullopt;
    }
    const std::string_view key = std::string_view(arg).substr(0, eq);
    const std::optional<double> value = number(std::string_view(arg).substr(eq + 1));
    if (!value) {
      error = fmt::format("{}: '{}' is not a number", key, arg.substr(eq + 1));
      return std::nullopt;
    }
    const auto in = [&](double lo, double hi) {
      if (*value >= lo && *value <= hi) return true;
      error = fmt::format("{}: {} is outside {}..{}", key, *value, lo, hi);
      return false;
    };
    if (key == "x") {
      hint.x_m = *value;
      has_x = true;
    } else if (key == "y") {
      hint.y_m = *value;
      has_y = true;
    } else if (key == "radius") {
      if (!in(0.5, 100.0)) return std::nullopt;
      hint.radius_m = *value;
    } else if (key == "heading") {
      hint.heading_deg = *value;
    } else if (key == "heading_tolerance") {
      if (!in(1.0, 180.0)) return std::nullopt;
      hint.heading_tolerance_deg = *value;
    } else {
      error = fmt::format("unknown argument '{}' (x, y, radius, heading, heading_tolerance)", key);
      return std::nullopt;
    }
  }
  if (!has_x || !has_y) {
    error = "x and y are needed (m, in the prior map's frame)";
    return std::nullopt;
  }
  return hint;
}

std::vector<std::string> localise_hint_args(const LocaliseHint& hint) {
  std::vector<std::string> args{fmt::format("x={}", hint.x_m), fmt::format("y={}", hint.y_m),
                                fmt::format("radius={}", hint.radius_m)};
  if (hint.heading_deg) {
    args.push_back(fmt::format("heading={}", *hint.heading_deg));
    args.push_back(fmt::format("heading_tolerance={}", hint.heading_tolerance_deg));
  }
  return args;
}

}  // namespace adit::protocol
