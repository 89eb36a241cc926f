#include "adit/eval/control_points.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <fstream>
#include <string>
#include <unordered_map>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "text_fields.hpp"

namespace adit::eval {
namespace {

enum Column { kId = 0, kE = 1, kN = 2, kH = 3 };
constexpr std::array<std::string_view, 4> kColumnNames{"id", "E", "N", "H"};

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

std::optional<Column> column_of(std::string_view name) {
  const std::string n = lower(name);
  if (n == "id" || n == "name" || n == "point" || n == "pt") return kId;
  if (n == "e" || n == "east" || n == "easting" || n == "x") return kE;
  if (n == "n" || n == "north" || n == "northing" || n == "y") return kN;
  if (n == "h" || n == "height" || n == "elevation" || n == "elev" || n == "z" || n == "rl") return kH;
  return std::nullopt;
}

// A header has a field after the first that is not a number.
bool looks_like_header(const std::vector<std::string_view>& fields) {
  return std::any_of(fields.begin() + (fields.empty() ? 0 : 1), fields.end(),
                     [](std::string_view f) { return !detail::parse_double(f); });
}

}  // namespace

std::optional<LengthUnit> parse_length_unit(std::string_view name) {
  if (name == "m") return LengthUnit::metre;
  if (name == "ft") return LengthUnit::foot;
  if (name == "usft") return LengthUnit::us_survey_foot;
  return std::nullopt;
}

double metres_per(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::metre: return 1.0;
    case LengthUnit::foot: return 0.3048;
    case LengthUnit::us_survey_foot: return 1200.0 / 3937.0;
  }
  return 1.0;
}

ControlFile read_control_points(const std::filesystem::path& path, LengthUnit unit) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), "", "cannot open for reading");
  return read_control_points(in, path, unit);
}

ControlFile read_control_points(std::istream& in, const std::filesystem::path& name, LengthUnit unit) {
  ControlFile file;
  file.name = name;
  std::array<std::size_t, 4> field_of{0, 1, 2, 3};  // column -> field index
  std::unordered_map<std::string, std::size_t> line_of_id;
  std::vector<std::string_view> fields;
  std::string line;
  bool first = true;
  const double scale = metres_per(unit);
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    if (detail::is_comment_or_blank(line)) continue;
    const std::string where = fmt::format("{}:{}", name.string(), number);
    detail::split_fields(line, ",", fields);
    if (first && looks_like_header(fields)) {
      first = false;
      if (fields.size() != 4)
        throw InputError(where, "header", fmt::format("expected 4 columns (id,E,N,H in any order), found {}", fields.size()));
      std::array<bool, 4> seen{};
      for (std::size_t k = 0; k < fields.size(); ++k) {
        const auto c = column_of(fields[k]);
        if (!c)
          throw InputError(where, "header",
                           fmt::format("'{}' is not a column name (id, E|easting, N|northing, H|height)", fields[k]));
        if (seen[*c]) throw InputError(where, "header", fmt::format("'{}' names column {} twice", fields[k], kColumnNames[*c]));
        seen[*c] = true;
        field_of[*c] = k;
      }
      file.header_line = number;
      continue;
    }
    first = false;
    if (fields.size() != 4)
      throw InputError(where, "", fmt::format("expected 4 fields (id,E,N,H), found {}", fields.size()));
    ControlPoint p;
    p.id = std::string(fields[field_of[kId]]);
    p.line = number;
    if (p.id.empty()) throw InputError(where, "id", "is empty");
    for (int c = kE; c <= kH; ++c) {
      const std::string_view f = fields[field_of[static_cast<std::size_t>(c)]];
      const auto v = detail::parse_double(f);
      if (!v) throw InputError(where, std::string(kColumnNames[static_cast<std::size_t>(c)]), fmt::format("'{}' is not a finite number", f));
      p.enh(c - 1) = *v * scale;
    }
    const auto [it, fresh] = line_of_id.emplace(p.id, number);
    if (!fresh) throw InputError(where, "id", fmt::format("'{}' appears twice (also line {})", p.id, it->second));
    file.points.push_back(std::move(p));
  }
  if (file.points.empty()) throw InputError(name.string(), "", "no control points");
  return file;
}

}  // namespace adit::eval
