#include "adit/drivers/lidar/scan_files.hpp"

#include <bit>
#include <cstdint>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "adit/common/error.hpp"

namespace adit::drivers {
namespace {

static_assert(std::endian::native == std::endian::little, "the binary formats here are little-endian");

std::string read_all(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot read");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> words(std::string_view line) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) out.emplace_back(line.substr(start, i - start));
  }
  return out;
}

struct PcdField {
  std::string name;
  std::size_t size = 4;
  char type = 'F';
  std::size_t count = 1;
  std::size_t offset = 0;  // in a binary record
};

// One value of a binary field as float.
float binary_value(const char* p, const PcdField& f) {
  switch (f.type) {
    case 'F':
      if (f.size == 4) {
        float v;
        std::memcpy(&v, p, 4);
        return v;
      } else {
        double v;
        std::memcpy(&v, p, 8);
        return static_cast<float>(v);
      }
    case 'U': {
      std::uint64_t v = 0;
      std::memcpy(&v, p, f.size);
      return static_cast<float>(v);
    }
    default: {  // 'I': sign-extend
      std::int64_t v = 0;
      std::memcpy(&v, p, f.size);
      const int shift = static_cast<int>(64 - 8 * f.size);
      return static_cast<float>((v << shift) >> shift);
    }
  }
}

}  // namespace

void read_pcd(const std::filesystem::path& file, std::vector<CloudPoint>& out) {
  out.clear();
  const std::string text = read_all(file);
  std::vector<PcdField> fields;
  std::size_t points = 0;
  std::string data;
  std::size_t pos = 0;
  int line_no = 0;
  auto where = [&] { return file.string() + ":" + std::to_string(line_no); };
  while (pos < text.size() && data.empty()) {
    const std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) throw InputError(where(), "", "header ends before DATA");
    const std::string_view line(text.data() + pos, end - pos);
    pos = end + 1;
    ++line_no;
    const auto w = words(line);
    if (w.empty() || w[0][0] == '#') continue;
    const std::string& key = w[0];
    auto number_of = [&](const std::string& s) {
      std::size_t v = 0;
      const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      if (ec != std::errc{} || p != s.data() + s.size()) throw InputError(where(), key, "not a number: " + s);
      return v;
    };
    if (key == "FIELDS") {
      for (std::size_t i = 1; i < w.size(); ++i) fields.push_back({w[i]});
    } else if (key == "SIZE" || key == "TYPE" || key == "COUNT") {
      if (w.size() != fields.size() + 1) throw InputError(where(), key, "does not list one entry per field");
      for (std::size_t i = 1; i < w.size(); ++i) {
        if (key == "SIZE") fields[i - 1].size = number_of(w[i]);
        if (key == "TYPE") fields[i - 1].type = w[i].size() == 1 ? w[i][0] : '?';
        if (key == "COUNT") fields[i - 1].count = number_of(w[i]);
      }
    } else if (key == "POINTS" && w.size() == 2) {
      points = number_of(w[1]);
    } else if (key == "DATA" && w.size() == 2) {
      data = w[1];
    }
  }
  if (data.empty()) throw InputError(file.string(), "DATA", "missing");
  int xi = -1, yi = -1, zi = -1, ii = -1;
  std::size_t record = 0;
  std::size_t values = 0;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    PcdField& f = fields[i];
    const bool size_ok = f.type == 'F' ? (f.size == 4 || f.size == 8)
                                       : (f.size == 1 || f.size == 2 || f.size == 4 || f.size == 8);
    if ((f.type != 'F' && f.type != 'U' && f.type != 'I') || !size_ok || f.count == 0 || f.count > 4096) {
      throw InputError(file.string(), "FIELDS", "field `" + f.name + "` has an unsupported TYPE/SIZE/COUNT");
    }
    f.offset = record;
    record += f.size * f.count;
    values += f.count;
    if (f.name == "x") xi = static_cast<int>(i);
    if (f.name == "y") yi = static_cast<int>(i);
    if (f.name == "z") zi = static_cast<int>(i);
    if (f.name == "intensity" || f.name == "reflectance" || f.name == "i") ii = static_cast<int>(i);
  }
  if (xi < 0 || yi < 0 || zi < 0) throw InputError(file.string(), "FIELDS", "needs x, y and z");
  if (points > (text.size() - pos) + 1 && data == "binary") {
    throw InputError(file.string(), "POINTS", "says " + std::to_string(points) + " but the file is shorter");
  }
  out.reserve(points);
  if (data == "binary") {
    if (text.size() - pos < points * record) {
      throw InputError(file.string(), "DATA", "binary data shorter than POINTS × the record size");
    }
    for (std::size_t k = 0; k < points; ++k) {
      const char* r = text.data() + pos + k * record;
      CloudPoint p;
      p.x = binary_value(r + fields[xi].offset, fields[xi]);
      p.y = binary_value(r + fields[yi].offset, fields[yi]);
      p.z = binary_value(r + fields[zi].offset, fields[zi]);
      if (ii >= 0) p.intensity = binary_value(r + fields[ii].offset, fields[ii]);
      out.push_back(p);
    }
  } else if (data == "ascii") {
    // Column of each field's first value.
    std::vector<std::size_t> column(fields.size());
    for (std::size_t i = 0, c = 0; i < fields.size(); c += fields[i].count, ++i) column[i] = c;
    while (pos < text.size() && out.size() < points) {
      std::size_t end = text.find('\n', pos);
      if (end == std::string::npos) end = text.size();
      const auto w = words(std::string_view(text.data() + pos, end - pos));
      pos = end + 1;
      ++line_no;
      if (w.empty()) continue;
      if (w.size() != values) throw InputError(where(), "DATA", "expected " + std::to_string(values) + " values");
      auto value = [&](int field) {
        float v = 0.0F;
        const std::string& s = w[column[static_cast<std::size_t>(field)]];
        const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
        if (ec != std::errc{} || p != s.data() + s.size()) throw InputError(where(), fields[field].name, "not a number: " + s);
        return v;
      };
      CloudPoint p{value(xi), value(yi), value(zi), ii >= 0 ? value(ii) : 0.0F};
      out.push_back(p);
    }
    if (out.size() != points) throw InputError(file.string(), "POINTS", "more points declared than present");
  } else {
    throw InputError(file.string(), "DATA", "`" + data + "` is not supported (want ascii or binary)");
  }
}

void read_kitti_bin(const std::filesystem::path& file, std::vector<CloudPoint>& out) {
  out.clear();
  const std::string bytes = read_all(file);
  if (bytes.size() % 16 != 0) throw InputError(file.string(), "", "size is not a multiple of 16 bytes (x y z r float32)");
  out.resize(bytes.size() / 16);
  std::memcpy(out.data(), bytes.data(), bytes.size());
}

namespace {
struct FileField {
  const char* name;
  char pcd_type;
  int size;
  const char* ply_type;
};
constexpr FileField kFields[] = {
    {"x", 'F', 4, "float"},          {"y", 'F', 4, "float"},        {"z", 'F', 4, "float"},
    {"intensity", 'F', 4, "float"},  {"range", 'F', 4, "float"},    {"time_offset_ns", 'U', 4, "uint"},
    {"ring", 'U', 2, "ushort"},      {"return_index", 'U', 1, "uchar"},
};
constexpr std::size_t kRecord = 4 * 6 + 2 + 1;

void write_records(std::ofstream& out, const LidarScan& scan) {
  std::vector<char> buffer(scan.points.size() * kRecord);
  char* p = buffer.data();
  for (const LidarPoint& q : scan.points) {
    std::memcpy(p, &q.x, 4);
    std::memcpy(p + 4, &q.y, 4);
    std::memcpy(p + 8, &q.z, 4);
    std::memcpy(p + 12, &q.intensity, 4);
    std::memcpy(p + 16, &q.range_m, 4);
    std::memcpy(p + 20, &q.time_offset_ns, 4);
    std::memcpy(p + 24, &q.ring, 2);
    std::memcpy(p + 26, &q.return_index, 1);
    p += kRecord;
  }
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
}

std::ofstream open_out(const std::filesystem::path& file) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw InputError(file.string(), "", "cannot write");
  return out;
}
}  // namespace

void write_pcd(const std::filesystem::path& file, const LidarScan& scan) {
  std::ofstream out = open_out(file);
  out << "# .PCD v0.7 - adit scan, start " << scan.start_time_ns << " ns (host), " << scan.sensor_start_time_ns
      << " ns (sensor)\nVERSION 0.7\nFIELDS";
  for (const auto& f : kFields) out << ' ' << f.name;
  out << "\nSIZE";
  for (const auto& f : kFields) out << ' ' << f.size;
  out << "\nTYPE";
  for (const auto& f : kFields) out << ' ' << f.pcd_type;
  out << "\nCOUNT";
  for (std::size_t i = 0; i < std::size(kFields); ++i) out << " 1";
  out << "\nWIDTH " << scan.points.size() << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << scan.points.size()
      << "\nDATA binary\n";
  write_records(out, scan);
  if (!out) throw InputError(file.string(), "", "write failed");
}

void write_ply(const std::filesystem::path& file, const LidarScan& scan) {
  std::ofstream out = open_out(file);
  out << "ply\nformat binary_little_endian 1.0\ncomment adit scan, start " << scan.start_time_ns
      << " ns (host)\nelement vertex " << scan.points.size() << '\n';
  for (const auto& f : kFields) out << "property " << f.ply_type << ' ' << f.name << '\n';
  out << "end_header\n";
  write_records(out, scan);
  if (!out) throw InputError(file.string(), "", "write failed");
}

}  // namespace adit::drivers
