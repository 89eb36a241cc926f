#include "adit/protocol/map_import.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/protocol/ply_header.hpp"

namespace adit::protocol {
namespace {

// The first bytes of a file that hold its header: PLY's and PCD's headers end
// within them (ply_header.hpp), LAS's public header block is 375 bytes.
constexpr std::size_t kHeadBytes = 64 * 1024;
// Points decoded per block when reading a file (2.5 MB of MapPoint).
constexpr std::size_t kBlockPoints = 64 * 1024;

template <typename T>
T load(std::string_view bytes, std::size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof v);  // little-endian host and files
  return v;
}

// One number of a point record: its binary type, where it lies in the record,
// and value = raw * scale + add (LAS scales integer coordinates).
struct Field {
  Scalar type = Scalar::f32;
  std::size_t offset = 0;
  double scale = 1.0;
  double add = 0.0;
};

double value(const Field& f, const char* record) { return read_scalar(f.type, record + f.offset) * f.scale + f.add; }

// Where a file's points lie and how each record is laid out.
struct Layout {
  std::uint64_t count = 0;
  std::size_t data_offset = 0;
  std::size_t record = 0;
  Field x, y, z;
  std::optional<Field> intensity, time;
};

// `count` records of `record` bytes from `offset` must fit in `size` bytes.
void check_size(std::uint64_t size, std::size_t offset, std::uint64_t count, std::size_t record,
                const std::string& name) {
  const std::uint64_t room = size >= offset ? size - offset : 0;
  if (record == 0 || count > room / record)
    throw InputError(name, "",
                     fmt::format("truncated: {} points of {} bytes need {} bytes after the header, file has {}", count,
                                 record, static_cast<double>(count) * record, room));
}

// The points of records [first, first + out.size()) from their bytes at `records`.
void decode(const Layout& l, const char* records, std::uint64_t first, std::span<MapPoint> out,
            const std::string& name) {
  for (std::size_t i = 0; i < out.size(); ++i) {
    const char* r = records + i * l.record;
    MapPoint& p = out[i];
    p.x = value(l.x, r);
    p.y = value(l.y, r);
    p.z = value(l.z, r);
    if (l.intensity) p.intensity = static_cast<float>(value(*l.intensity, r));
    if (l.time) p.time = value(*l.time, r);
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw InputError(name, fmt::format("point {}", first + i), "non-finite coordinate");
  }
}

Layout ply_layout(std::string_view head, const std::string& name) {
  const PlyHeader header = parse_ply_header(head, name);
  if (header.elements.empty() || header.elements.front().name != "vertex")
    throw InputError(name, "element vertex", "the first element must be 'vertex'");
  const PlyElement& vertex = header.elements.front();
  Layout l;
  l.count = vertex.count;
  l.data_offset = header.data_offset;
  std::optional<Field> x, y, z;
  for (const PlyProperty& p : vertex.properties) {
    if (!p.count_type.empty()) throw InputError(name, "property " + p.name, "list properties in 'vertex' are not read");
    const std::optional<Scalar> type = ply_scalar(p.type);
    if (!type) throw InputError(name, "property " + p.name, fmt::format("unknown type '{}'", p.type));
    const Field f{*type, l.record};
    if (p.name == "x") x = f;
    if (p.name == "y") y = f;
    if (p.name == "z") z = f;
    if (p.name == "intensity") l.intensity = f;
    l.record += scalar_size(*type);
  }
  if (!x || !y || !z) throw InputError(name, "element vertex", "needs properties x, y and z");
  l.x = *x;
  l.y = *y;
  l.z = *z;
  return l;
}

// PCD v0.7 (pointclouds.org, "The PCD (Point Cloud Data) file format").
Layout pcd_layout(std::string_view bytes, const std::string& name) {
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
  Layout l;
  l.count = *points_count;
  l.data_offset = offset;
  std::optional<Field> x, y, z;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const char t = types[i][0];
    const std::size_t s = sizes[i];
    std::optional<Scalar> type;
    if (t == 'F' && s == 4) type = Scalar::f32;
    if (t == 'F' && s == 8) type = Scalar::f64;
    if (t == 'I') type = s == 1 ? Scalar::i8 : s == 2 ? Scalar::i16 : s == 4 ? Scalar::i32 : Scalar::i64;
    if (t == 'U') type = s == 1 ? Scalar::u8 : s == 2 ? Scalar::u16 : s == 4 ? Scalar::u32 : Scalar::u64;
    if (!type || (t != 'F' && s != 1 && s != 2 && s != 4 && s != 8))
      throw InputError(name, "SIZE", fmt::format("field {}: {} {} is not a binary number type", fields[i], types[i], s));
    const Field f{*type, l.record};
    if (fields[i] == "x") x = f;
    if (fields[i] == "y") y = f;
    if (fields[i] == "z") z = f;
    if (fields[i] == "intensity") l.intensity = f;
    l.record += s * counts[i];
  }
  if (!x || !y || !z) throw InputError(name, "FIELDS", "needs fields x, y and z");
  l.x = *x;
  l.y = *y;
  l.z = *z;
  return l;
}

// LAS 1.0-1.4 (ASPRS LAS 1.4 R15, Table 3 header; §2.6 point data records).
// `size`: the whole file's, of which `head` is the start.
Layout las_layout(std::string_view head, std::uint64_t size, const std::string& name) {
  constexpr std::size_t kMinHeader = 227;  // LAS 1.0-1.2 public header block
  if (head.size() < kMinHeader || head.substr(0, 4) != "LASF")
    throw InputError(name, "", "not a LAS file (no 'LASF' signature or shorter than a header)");
  const auto major = load<std::uint8_t>(head, 24);
  const auto minor = load<std::uint8_t>(head, 25);
  if (major != 1 || minor > 4)
    throw InputError(name, "version", fmt::format("LAS {}.{} is not read (1.0-1.4 are)", major, minor));
  const auto header_size = load<std::uint16_t>(head, 94);
  const auto data_offset = load<std::uint32_t>(head, 96);
  const auto format_byte = load<std::uint8_t>(head, 104);
  const auto record = load<std::uint16_t>(head, 105);
  if (format_byte & 0xC0) throw InputError(name, "point data format", "compressed (LAZ) points are not read");
  // Record lengths of point data record formats 0-10 (Tables 7-17).
  constexpr std::array<std::size_t, 11> kMinRecord{20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  if (format_byte > 10) throw InputError(name, "point data format", fmt::format("{} is not 0-10", format_byte));
  if (record < kMinRecord[format_byte])
    throw InputError(name, "point data record length",
                     fmt::format("{} bytes is short for format {} ({})", record, format_byte, kMinRecord[format_byte]));
  if (header_size < kMinHeader || data_offset < header_size || data_offset > size)
    throw InputError(name, "offset to point data",
                     fmt::format("{} (header size {}, file {} bytes)", data_offset, header_size, size));
  Layout l;
  l.count = load<std::uint32_t>(head, 107);  // legacy count
  if (minor >= 4 && header_size >= 375 && head.size() >= 255)
    l.count = std::max(l.count, load<std::uint64_t>(head, 247));
  l.data_offset = data_offset;
  l.record = record;
  Field* axes[] = {&l.x, &l.y, &l.z};
  for (int a = 0; a < 3; ++a) {
    const double scale = load<double>(head, 131 + 8 * a);
    const double offset = load<double>(head, 155 + 8 * a);
    if (!(scale > 0.0) || !std::isfinite(scale) || !std::isfinite(offset))
      throw InputError(name, "scale/offset", "scale factors must be positive and offsets finite");
    *axes[a] = Field{Scalar::i32, static_cast<std::size_t>(4 * a), scale, offset};
  }
  l.intensity = Field{Scalar::u16, 12};
  // GPS time follows the 20-byte core in formats 1, 3-5, the 22-byte core in 6-10;
  // Adjusted Standard GPS Time goes back to Unix seconds.
  const int time_at = format_byte >= 6 ? 22 : (format_byte == 1 || format_byte >= 3) ? 20 : -1;
  const bool adjusted_gps = (load<std::uint16_t>(head, 6) & 1) != 0;
  if (time_at >= 0)
    l.time = Field{Scalar::f64, static_cast<std::size_t>(time_at), 1.0,
                   adjusted_gps ? 1e9 + kGpsEpochUnixSeconds - kGpsLeapSeconds : 0.0};
  return l;
}

Layout layout_of(std::string_view head, std::uint64_t size, MapFormat format, const std::string& name) {
  Layout l;
  switch (format) {
    case MapFormat::ply: l = ply_layout(head, name); break;
    case MapFormat::pcd: l = pcd_layout(head, name); break;
    case MapFormat::las: l = las_layout(head, size, name); break;
  }
  check_size(size, l.data_offset, l.count, l.record, name);
  return l;
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
  const Layout l = layout_of(bytes, bytes.size(), format, name);
  std::vector<MapPoint> points(l.count);
  decode(l, bytes.data() + l.data_offset, 0, points, name);
  return points;
}

struct MapFileReader::Impl {
  std::string name;
  std::ifstream in;
  Layout layout;
  std::uint64_t next_point = 0;
  std::string bytes;
  std::vector<MapPoint> block;
};

MapFileReader::MapFileReader(const std::filesystem::path& file) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  const MapFormat format = map_format_of(file);
  m.name = file.string();
  m.in.open(file, std::ios::binary);
  if (!m.in) throw InputError(m.name, "", "cannot open the map file");
  std::error_code error;
  const std::uint64_t size = std::filesystem::file_size(file, error);
  if (error) throw InputError(m.name, "", "cannot read the map file's size: " + error.message());
  std::string head(static_cast<std::size_t>(std::min<std::uint64_t>(size, kHeadBytes)), '\0');
  if (!m.in.read(head.data(), static_cast<std::streamsize>(head.size())))
    throw InputError(m.name, "", "cannot read the map file's header");
  m.layout = layout_of(head, size, format, m.name);
  m.in.seekg(static_cast<std::streamoff>(m.layout.data_offset));
  const auto block = static_cast<std::size_t>(std::min<std::uint64_t>(kBlockPoints, m.layout.count));
  m.bytes.resize(block * m.layout.record);
  m.block.resize(block);
}

MapFileReader::~MapFileReader() = default;

std::uint64_t MapFileReader::count() const { return impl_->layout.count; }

std::span<const MapPoint> MapFileReader::next() {
  Impl& m = *impl_;
  const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(m.block.size(), m.layout.count - m.next_point));
  if (n == 0) return {};
  if (!m.in.read(m.bytes.data(), static_cast<std::streamsize>(n * m.layout.record)))
    throw InputError(m.name, fmt::format("point {}", m.next_point), "the file ended early (changed while read?)");
  const std::span<MapPoint> out(m.block.data(), n);
  decode(m.layout, m.bytes.data(), m.next_point, out, m.name);
  m.next_point += n;
  return out;
}

std::vector<MapPoint> read_map(const std::filesystem::path& file) {
  MapFileReader reader(file);
  std::vector<MapPoint> points;
  points.reserve(static_cast<std::size_t>(reader.count()));
  for (std::span<const MapPoint> block = reader.next(); !block.empty(); block = reader.next())
    points.insert(points.end(), block.begin(), block.end());
  return points;
}

}  // namespace adit::protocol
