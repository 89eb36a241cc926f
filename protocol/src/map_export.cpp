#include "adit/protocol/map_export.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <fstream>
#include <limits>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::protocol {
namespace {

// Appends little-endian values (the host is little-endian: x86-64, aarch64).
class Bytes {
 public:
  template <typename T>
  void put(T value) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
    data_.insert(data_.end(), p, p + sizeof(T));
  }
  void put_text(std::string_view text, std::size_t width) {
    for (std::size_t i = 0; i < width; ++i) data_.push_back(i < text.size() ? static_cast<std::uint8_t>(text[i]) : 0);
  }
  void append(std::string_view text) { data_.insert(data_.end(), text.begin(), text.end()); }
  std::size_t size() const { return data_.size(); }
  const std::vector<std::uint8_t>& data() const { return data_; }

 private:
  std::vector<std::uint8_t> data_;
};

void save(const std::filesystem::path& file, const Bytes& bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (out) out.write(reinterpret_cast<const char*>(bytes.data().data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw InputError(file.string(), "", "cannot write the map file");
}

Bytes ply(std::span<const MapPoint> points) {
  Bytes b;
  b.append(fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment adit map\nelement vertex {}\n"
      "property float x\nproperty float y\nproperty float z\nproperty float intensity\nend_header\n",
      points.size()));
  for (const MapPoint& p : points) {
    b.put(static_cast<float>(p.x));
    b.put(static_cast<float>(p.y));
    b.put(static_cast<float>(p.z));
    b.put(p.intensity);
  }
  return b;
}

// PCD v0.7 (pointclouds.org file format): ASCII header, binary records.
Bytes pcd(std::span<const MapPoint> points) {
  Bytes b;
  b.append(fmt::format(
      "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\n"
      "TYPE F F F F\nCOUNT 1 1 1 1\nWIDTH {0}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {0}\nDATA binary\n",
      points.size()));
  for (const MapPoint& p : points) {
    b.put(static_cast<float>(p.x));
    b.put(static_cast<float>(p.y));
    b.put(static_cast<float>(p.z));
    b.put(p.intensity);
  }
  return b;
}

// LAS 1.4 R15 (ASPRS, 2019), Table 3 (public header block, 375 bytes) and
// Table 13 (point data record format 6, 30 bytes). No VLRs, no EVLRs.
Bytes las(std::span<const MapPoint> points) {
  std::array<double, 3> lo{0, 0, 0};
  std::array<double, 3> hi{0, 0, 0};
  if (!points.empty()) {
    lo = {points[0].x, points[0].y, points[0].z};
    hi = lo;
    for (const MapPoint& p : points) {
      const std::array<double, 3> v{p.x, p.y, p.z};
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], v[a]);
        hi[a] = std::max(hi[a], v[a]);
      }
    }
  }
  // Offsets at whole metres below the minimum keep the integers small and
  // positive; 1 mm scale then spans 2 147 km, far beyond any survey.
  std::array<double, 3> offset{};
  for (int a = 0; a < 3; ++a) offset[a] = std::floor(lo[a]);
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);

  Bytes b;
  b.put_text("LASF", 4);
  b.put<std::uint16_t>(0);  // file source id
  // Global encoding: bit 0 = Adjusted Standard GPS Time, bit 4 = WKT (must be
  // set for point formats 6-10).
  b.put<std::uint16_t>((1u << 0) | (1u << 4));
  b.put<std::uint32_t>(0);  // project id GUID data 1..4
  b.put<std::uint16_t>(0);
  b.put<std::uint16_t>(0);
  b.put_text("", 8);
  b.put<std::uint8_t>(1);  // version major
  b.put<std::uint8_t>(4);  // version minor
  b.put_text("OTHER", 32);  // system identifier (§ "Generating a LAS file": OTHER when not from a sensor)
  b.put_text("adit", 32);   // generating software
  b.put<std::uint16_t>(static_cast<std::uint16_t>(utc.tm_yday + 1));
  b.put<std::uint16_t>(static_cast<std::uint16_t>(utc.tm_year + 1900));
  b.put<std::uint16_t>(kLasHeaderSize);
  b.put<std::uint32_t>(kLasHeaderSize);  // offset to point data: no VLRs
  b.put<std::uint32_t>(0);               // number of VLRs
  b.put<std::uint8_t>(6);                // point data record format
  b.put<std::uint16_t>(kLasPointFormat6Length);
  b.put<std::uint32_t>(0);  // legacy point count: must be 0 for formats 6-10
  for (int i = 0; i < 5; ++i) b.put<std::uint32_t>(0);  // legacy points by return
  for (int a = 0; a < 3; ++a) b.put<double>(kLasScale);
  for (int a = 0; a < 3; ++a) b.put<double>(offset[a]);
  for (int a = 0; a < 3; ++a) {
    b.put<double>(hi[a]);
    b.put<double>(lo[a]);
  }
  b.put<std::uint64_t>(0);  // start of waveform data packet record
  b.put<std::uint64_t>(0);  // start of first EVLR
  b.put<std::uint32_t>(0);  // number of EVLRs
  b.put<std::uint64_t>(points.size());
  b.put<std::uint64_t>(points.size());  // every point is return 1 of 1
  for (int i = 1; i < 15; ++i) b.put<std::uint64_t>(0);

  const auto scaled = [](double v, double off) {
    return static_cast<std::int32_t>(std::llround((v - off) / kLasScale));
  };
  for (const MapPoint& p : points) {
    b.put<std::int32_t>(scaled(p.x, offset[0]));
    b.put<std::int32_t>(scaled(p.y, offset[1]));
    b.put<std::int32_t>(scaled(p.z, offset[2]));
    b.put<std::uint16_t>(static_cast<std::uint16_t>(std::clamp(p.intensity, 0.0f, 65535.0f)));
    b.put<std::uint8_t>(0x11);  // return number 1 (bits 0-3), number of returns 1 (bits 4-7)
    b.put<std::uint8_t>(0);     // classification flags, scanner channel, scan direction, edge
    b.put<std::uint8_t>(1);     // classification: unclassified
    b.put<std::uint8_t>(0);     // user data
    b.put<std::int16_t>(0);     // scan angle
    b.put<std::uint16_t>(0);    // point source id
    b.put<double>(adjusted_standard_gps_time(p.time));
  }
  return b;
}

}  // namespace

double adjusted_standard_gps_time(double unix_seconds) {
  return unix_seconds - kGpsEpochUnixSeconds + kGpsLeapSeconds - 1e9;
}

std::optional<MapFormat> parse_map_format(std::string_view name) {
  if (name == "ply") return MapFormat::ply;
  if (name == "pcd") return MapFormat::pcd;
  if (name == "las") return MapFormat::las;
  return std::nullopt;
}

void write_map(const std::filesystem::path& file, MapFormat format, std::span<const MapPoint> points) {
  switch (format) {
    case MapFormat::ply: save(file, ply(points)); return;
    case MapFormat::pcd: save(file, pcd(points)); return;
    case MapFormat::las: save(file, las(points)); return;
  }
}

}  // namespace adit::protocol
