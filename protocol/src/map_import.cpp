#include "adit/protocol/map_import.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/protocol/ply_header.hpp"

namespace adit::protocol {
namespace {

template <typename T>
T load(std::string_view bytes, std::size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof v);  // little-endian host and files
  return v;
}

// `count` records of `record` bytes from `offset` must fit in the file.
void check_size(std::string_view bytes, std::size_t offset, std::uint64_t count, std::size_t record,
                const std::string& name) {
  const std::size_t room = bytes.size() >= offset ? bytes.size() - offset : 0;
  if (record == 0 || count > room / record)
    throw InputError(name, "",
                     fmt::format("truncated: {} points of {} bytes need {} bytes after the header, file has {}", count,
                                 record, static_cast<double>(count) * record, room));
}

void check_finite(const MapPoint& p, std::size_t index, const std::string& name) {
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
    throw InputError(name, fmt::format("point {}", index), "non-finite coordinate");
}

std::vector<MapPoint> read_ply_map(std::string_view bytes, const std::string& name) {
  const PlyHeader header = parse_ply_header(bytes, name);
  if (header.elements.empty() || header.elements.front().name != "vertex")
    throw InputError(name, "element vertex", "the first element must be 'vertex'");
  const PlyElement& vertex = header.elements.front();
  struct Field {
    std::string type;
    std::size_t offset = 0;
  };
  std::optional<Field> x, y, z, intensity;
  std::size_t record = 0;
  for (const PlyProperty& p : vertex.properties) {
    if (!p.count_type.empty()) throw InputError(name, "property " + p.name, "list properties in 'vertex' are not read");
    const Field f{p.type, record};
    if (p.name == "x") x = f;
    if (p.name == "y") y = f;
    if (p.name == "z") z = f;
    if (p.name == "intensity") intensity = f;
    record += ply_type_size(p.type);
  }
  if (!x || !y || !z) throw InputError(name, "element vertex", "needs properties x, y and z");
  check_size(bytes, header.data_offset, vertex.count, record, name);
  std::vector<MapPoint> points(vertex.count);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const char* r = bytes.data() + header.data_offset + i * record;
    MapPoint& p = points[i];
    p.x = read_ply_scalar(x->type, r + x->offset);
    p.y = read_ply_scalar(y->type, r + y->offset);
    p.z = read_ply_scalar(z->type, r + z->offset);
    if (intensity) p.intensity = static_cast<float>(read_ply_scalar(intensity->type, r + intensity->offset));
    check_finite(p, i, name);
  }
  return points;
}

// PCD v0.7 (pointclouds.org, "The PCD (Point Cloud Data) file format").
std::vector<MapPoint> read_pcd_map(std::string_view bytes, const std::string& name) {
  std::vector<std::string> fields, types;
  std::vector<std::size_t> sizes, counts;
  std::optional<std::uint64_t> points_count;
  std::size_t offset = 0;
  int line_number = 0;
  bool data = false;
  while (!data) {
    const std::size_t eol = bytes.find('\n', offset);
    if (eol == std::string_view::npos || line_number > 64)
      throw InputError(name, "", "not a PCD file (no 'DATA' line in the header)");
    const std::string line(bytes.substr(offset, eol - offset));
    offset = eol + 1;
    ++line_number;
    const std::string where = fmt::format("{}:{}", name, line_number);
    std::istringstream words(line);
    std::string key;
    words >> key;
    const auto numbers = [&](std::size_t max) {
      std::vector<std::size_t> out;
      std::string w;
      while (words >> w) {
        std::size_t used = 0;
        std::size_t v = 0;
        try {
          v = std::stoul(w, &used);
        } catch (const std::exception&) {
        }
        if (used != w.size() || v == 0 || v > max)
          throw InputError(where, key, fmt::format("'{}' is not 1..{}", w, max));
        out.push_back(v);
      }
      return out;
    };
    if (key.empty() || key[0] == '#' || key == "VERSION" || key == "VIEWPOINT" || key == "WIDTH" || key == "HEIGHT") {
      continue;
    } else if (key == "FIELDS") {
      for (std::string w; words >> w;) fields.push_back(w);
    } else if (key == "SIZE") {
      sizes = numbers(8);
    } else if (key == "COUNT") {
      counts = numbers(4096);
    } else if (key == "TYPE") {
      for (std::string w; words >> w;) {
        if (w != "F" && w != "I" && w != "U") throw InputError(where, key, fmt::format("'{}' is not F, I or U", w));
        types.push_back(w);
      }
    } else if (key == "POINTS") {
      std::uint64_t n = 0;
      if (!(words >> n)) throw InputError(where, key, "expected a count");
      points_count = n;
    } else if (key == "DATA") {
      std::string kind;
      words >> kind;
      if (kind != "binary") throw InputError(where, key, fmt::format("'{}': only 'DATA binary' is read", kind));
      data = true;
    } else {
      throw InputError(where, key, "unknown header keyword");
    }
  }
  if (counts.empty()) counts.assign(fields.size(), 1);
  if (fields.empty() || sizes.size() != fields.size() || types.size() != fields.size() ||
      counts.size() != fields.size())
    throw InputError(name, "FIELDS", "FIELDS, SIZE, TYPE and COUNT must list the same number of fields");
  if (!points_count) throw InputError(name, "POINTS", "the header has no POINTS line");
  struct Field {
    char type = 'F';
    std::size_t size = 4;
    std::size_t offset = 0;
  };
  std::optional<Field> x, y, z, intensity;
  std::size_t record = 0;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const Field f{types[i][0], sizes[i], record};
    const bool number = f.size == 4 || f.size == 8 || (f.type != 'F' && (f.size == 1 || f.size == 2));
    if (!number)
      throw InputError(name, "SIZE",
                       fmt::format("field {}: {} {} is not a binary number type", fields[i], types[i], sizes[i]));
    if (fields[i] == "x") x = f;
    if (fields[i] == "y") y = f;
    if (fields[i] == "z") z = f;
    if (fields[i] == "intensity") intensity = f;
    record += sizes[i] * counts[i];
  }
  if (!x || !y || !z) throw InputError(name, "FIELDS", "needs fields x, y and z");
  check_size(bytes, offset, *points_count, record, name);
  const auto value = [&](const Field& f, std::size_t at) -> double {
    switch (f.type) {
      case 'F':
        return f.size == 4 ? load<float>(bytes, at) : load<double>(bytes, at);
      case 'I':
        return f.size == 1   ? load<std::int8_t>(bytes, at)
               : f.size == 2 ? load<std::int16_t>(bytes, at)
               : f.size == 4 ? load<std::int32_t>(bytes, at)
                             : static_cast<double>(load<std::int64_t>(bytes, at));
      default:
        return f.size == 1   ? load<std::uint8_t>(bytes, at)
               : f.size == 2 ? load<std::uint16_t>(bytes, at)
               : f.size == 4 ? load<std::uint32_t>(bytes, at)
                             : static_cast<double>(load<std::uint64_t>(bytes, at));
    }
  };
  std::vector<MapPoint> points(*points_count);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::size_t r = offset + i * record;
    MapPoint& p = points[i];
    p.x = value(*x, r + x->offset);
    p.y = value(*y, r + y->offset);
    p.z = value(*z, r + z->offset);
    if (intensity) p.intensity = static_cast<float>(value(*intensity, r + intensity->offset));
    check_finite(p, i, name);
  }
  return points;
}

// LAS 1.0-1.4 (ASPRS LAS 1.4 R15, Table 3 header; §2.6 point data records).
std::vector<MapPoint> read_las_map(std::string_view bytes, const std::string& name) {
  constexpr std::size_t kMinHeader = 227;  // LAS 1.0-1.2 public header block
  if (bytes.size() < kMinHeader || bytes.substr(0, 4) != "LASF")
    throw InputError(name, "", "not a LAS file (no 'LASF' signature or shorter than a header)");
  const auto major = load<std::uint8_t>(bytes, 24);
  const auto minor = load<std::uint8_t>(bytes, 25);
  if (major != 1 || minor > 4)
    throw InputError(name, "version", fmt::format("LAS {}.{} is not read (1.0-1.4 are)", major, minor));
  const auto header_size = load<std::uint16_t>(bytes, 94);
  const auto data_offset = load<std::uint32_t>(bytes, 96);
  const auto format_byte = load<std::uint8_t>(bytes, 104);
  const auto record = load<std::uint16_t>(bytes, 105);
  if (format_byte & 0xC0) throw InputError(name, "point data format", "compressed (LAZ) points are not read");
  // Record lengths of point data record formats 0-10 (Tables 7-17).
  constexpr std::array<std::size_t, 11> kMinRecord{20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  if (format_byte > 10) throw InputError(name, "point data format", fmt::format("{} is not 0-10", format_byte));
  if (record < kMinRecord[format_byte])
    throw InputError(name, "point data record length",
                     fmt::format("{} bytes is short for format {} ({})", record, format_byte, kMinRecord[format_byte]));
  if (header_size < kMinHeader || data_offset < header_size || data_offset > bytes.size())
    throw InputError(name, "offset to point data",
                     fmt::format("{} (header size {}, file {} bytes)", data_offset, header_size, bytes.size()));
  std::uint64_t count = load<std::uint32_t>(bytes, 107);  // legacy count
  if (minor >= 4 && header_size >= 375 && bytes.size() >= 255) count = std::max(count, load<std::uint64_t>(bytes, 247));
  std::array<double, 3> scale{}, offset{};
  for (int a = 0; a < 3; ++a) {
    scale[a] = load<double>(bytes, 131 + 8 * a);
    offset[a] = load<double>(bytes, 155 + 8 * a);
    if (!(scale[a] > 0.0) || !std::isfinite(scale[a]) || !std::isfinite(offset[a]))
      throw InputError(name, "scale/offset", "scale factors must be positive and offsets finite");
  }
  check_size(bytes, data_offset, count, record, name);
  // GPS time follows the 20-byte core in formats 1, 3-5, the 22-byte core in 6-10.
  const int time_at = format_byte >= 6 ? 22 : (format_byte == 1 || format_byte >= 3) ? 20 : -1;
  const bool adjusted_gps = (load<std::uint16_t>(bytes, 6) & 1) != 0;
  std::vector<MapPoint> points(count);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::size_t r = data_offset + i * record;
    MapPoint& p = points[i];
    p.x = load<std::int32_t>(bytes, r) * scale[0] + offset[0];
    p.y = load<std::int32_t>(bytes, r + 4) * scale[1] + offset[1];
    p.z = load<std::int32_t>(bytes, r + 8) * scale[2] + offset[2];
    p.intensity = load<std::uint16_t>(bytes, r + 12);
    if (time_at >= 0) {
      const double t = load<double>(bytes, r + time_at);
      // Back to Unix seconds when the time is Adjusted Standard GPS Time.
      p.time = adjusted_gps ? t + 1e9 + kGpsEpochUnixSeconds - kGpsLeapSeconds : t;
    }
  }
  return points;
}

}  // namespace

MapFormat map_format_of(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".ply") return MapFormat::ply;
  if (ext == ".pcd") return MapFormat::pcd;
  if (ext == ".las") return MapFormat::las;
  throw InputError(file.string(), "", "unknown map format: the name must end in .ply, .pcd or .las");
}

std::vector<MapPoint> read_map(std::string_view bytes, MapFormat format, const std::string& name) {
  switch (format) {
    case MapFormat::ply:
      return read_ply_map(bytes, name);
    case MapFormat::pcd:
      return read_pcd_map(bytes, name);
    case MapFormat::las:
      return read_las_map(bytes, name);
  }
  return {};
}

std::vector<MapPoint> read_map(const std::filesystem::path& file) {
  const MapFormat format = map_format_of(file);
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot open the map file");
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return read_map(bytes, format, file.string());
}

}  // namespace adit::protocol
