// Hesai angle-correction CSV: one row per channel, "id,elevation,azimuth" in
// degrees, after an optional header row ("Channel,Elevation,Azimuth" or
// "Laser id,Elevation,Azimuth" depending on the model and firmware).

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/hesai.hpp"

namespace adit::drivers {
namespace {

std::string_view trim(std::string_view s) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '"'; };
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

std::optional<double> to_number(std::string_view s) {
  s = trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || end != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

constexpr std::array<std::string_view, 3> kColumns = {"id", "elevation", "azimuth"};

}  // namespace

HesaiAngleCorrection parse_hesai_angle_csv(std::string_view text, const std::string& source) {
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  HesaiAngleCorrection out;
  std::size_t line_no = 0;
  std::optional<long> next_id;
  while (!text.empty()) {
    const std::size_t eol = text.find('\n');
    const std::string_view line = trim(text.substr(0, eol));
    text = eol == std::string_view::npos ? std::string_view{} : text.substr(eol + 1);
    ++line_no;
    if (line.empty()) continue;
    const std::string where = fmt::format("{}:{}", source, line_no);

    std::array<std::string_view, 3> cells;
    std::string_view rest = line;
    std::size_t n = 0;
    while (n < cells.size()) {
      const std::size_t comma = rest.find(',');
      cells[n++] = trim(rest.substr(0, comma));
      if (comma == std::string_view::npos) break;
      rest = rest.substr(comma + 1);
    }
    if (!to_number(cells[0])) {
      if (out.elevation_deg.empty() && !next_id) continue;  // the header row
      throw InputError(where, "id", fmt::format("expected a channel number, got '{}'", cells[0]));
    }
    if (n < 3) throw InputError(where, "azimuth", "expected 3 columns: id, elevation, azimuth");
    std::array<double, 3> v{};
    for (std::size_t i = 0; i < 3; ++i) {
      const auto num = to_number(cells[i]);
      if (!num) throw InputError(where, std::string(kColumns[i]), fmt::format("not a number: '{}'", cells[i]));
      v[i] = *num;
    }
    const long id = std::lround(v[0]);
    if (static_cast<double>(id) != v[0] || (next_id && id != *next_id) || (!next_id && id != 0 && id != 1)) {
      throw InputError(where, "id", fmt::format("channel {} out of sequence (expected {})", cells[0],
                                                next_id ? *next_id : 1));
    }
    next_id = id + 1;
    if (std::abs(v[1]) > 90.0) throw InputError(where, "elevation", "outside [-90, 90] degrees");
    if (std::abs(v[2]) > 180.0) throw InputError(where, "azimuth", "outside [-180, 180] degrees");
    out.elevation_deg.push_back(static_cast<float>(v[1]));
    out.azimuth_deg.push_back(static_cast<float>(v[2]));
    if (out.elevation_deg.size() > 512) throw InputError(where, "id", "more than 512 channels");
  }
  if (out.elevation_deg.empty()) throw InputError(source, "id", "no channel rows");
  return out;
}

HesaiAngleCorrection load_hesai_angle_csv(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "calibration", "cannot open the angle-correction file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_hesai_angle_csv(text.str(), file.string());
}

}  // namespace adit::drivers
