#pragma once
// Control points as a total station exports them: CSV `id,E,N,H` (easting,
// northing, height), one point a line, '#' comments. A header line is
// optional; when present it names the columns, in any order (`id,N,E,H` is
// read as such): id | name | point | pt; E | east | easting | x;
// N | north | northing | y; H | height | elevation | elev | z | rl
// (case-insensitive). Without a header the order is id,E,N,H.
//
// Units: the file does not say (total stations export bare numbers), so the
// caller states them; a file in feet read as metres is caught later by the
// fit (georeference.hpp: the distances come out 3.28 times the map's).
// Coordinates are kept as doubles in metres: site grids reach E ~ 500 000,
// N ~ 7 000 000, where a float keeps only decimetres.

#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace adit::eval {

enum class LengthUnit { metre, foot, us_survey_foot };
// "m", "ft" (international foot, 0.3048 m), "usft" (US survey foot, 1200/3937 m); nullopt otherwise.
std::optional<LengthUnit> parse_length_unit(std::string_view name);
double metres_per(LengthUnit unit);

struct ControlPoint {
  std::string id;
  Eigen::Vector3d enh = Eigen::Vector3d::Zero();  // E, N, H in metres
  std::size_t line = 0;                           // in the file, from 1
};

struct ControlFile {
  std::filesystem::path name;
  std::vector<ControlPoint> points;
  std::size_t header_line = 0;  // 0: no header (the order id,E,N,H was assumed)
};

// Throws adit::InputError("file:line", key, what) for a malformed line, an
// unknown or repeated header column, a duplicate id (naming both lines) or a
// file without points.
ControlFile read_control_points(const std::filesystem::path& path, LengthUnit unit);
ControlFile read_control_points(std::istream& in, const std::filesystem::path& name, LengthUnit unit);

}  // namespace adit::eval
