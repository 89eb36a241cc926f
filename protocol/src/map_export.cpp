#include "adit/protocol/map_export.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <fstream>
#include <limits>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::protocol {
namespace {

// Appends little-endian values (the host is little-endian: x86-64, aarch64).
class Bytes {
 public:
  // Reserved up front: GCC 12 warns falsely (-Warray-bounds) about growing a vector from a few bytes.
  explicit Bytes(std::size_t capacity) { data_.reserve(capacity); }
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

std::string ply_header(std::uint64_t n, bool doubles) {
  return fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment adit map\nelement vertex {0}\n"
      "property {1} x\nproperty {1} y\nproperty {1} z\nproperty float intensity\nend_header\n",
      n, doubles ? "double" : "float");
}

// PCD v0.7 (pointclouds.org file format): ASCII header, binary records.
std::string pcd_header(std::uint64_t n) {
  return fmt::format(
      "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\n"
      "TYPE F F F F\nCOUNT 1 1 1 1\nWIDTH {0}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {0}\nDATA binary\n",
      n);
}

void put_float_xyzi(Bytes& b, const MapPoint& p) {
  b.put(static_cast<float>(p.x));
  b.put(static_cast<float>(p.y));
  b.put(static_cast<float>(p.z));
  b.put(p.intensity);
}

void put_double_xyz_float_i(Bytes& b, const MapPoint& p) {
  b.put(p.x);
  b.put(p.y);
  b.put(p.z);
  b.put(p.intensity);
}

// The VLR bytes before the points: one WKT record, or nothing.
std::size_t las_vlr_size(const std::string& wkt) { return wkt.empty() ? 0 : kLasVlrHeaderSize + wkt.size() + 1; }

// LAS 1.4 R15 (ASPRS, 2019), Table 3 (public header block, 375 bytes) and
// Table 13 (point data record format 6, 30 bytes). No EVLRs; one VLR (the
// CRS as WKT, Table 4 and "OGC Coordinate System WKT Record") when `wkt` is
// given, else none.
Bytes las_header(std::uint64_t n, const std::array<double, 3>& offset, const std::array<double, 3>& lo,
                 const std::array<double, 3>& hi, const std::string& wkt) {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);

  Bytes b(kLasHeaderSize);
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
  b.put<std::uint32_t>(static_cast<std::uint32_t>(kLasHeaderSize + las_vlr_size(wkt)));  // offset to point data
  b.put<std::uint32_t>(wkt.empty() ? 0 : 1);                                              // number of VLRs
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
  b.put<std::uint64_t>(n);
  b.put<std::uint64_t>(n);  // every point is return 1 of 1
  for (int i = 1; i < 15; ++i) b.put<std::uint64_t>(0);
  if (!wkt.empty()) {  // Table 4: the VLR header, then the record
    b.put<std::uint16_t>(0);  // reserved
    b.put_text("LASF_Projection", 16);
    b.put<std::uint16_t>(kLasWktRecordId);
    b.put<std::uint16_t>(static_cast<std::uint16_t>(wkt.size() + 1));
    b.put_text("OGC coordinate system WKT", 32);
    b.append(wkt);
    b.put<std::uint8_t>(0);
  }
  return b;
}

void put_las_point(Bytes& b, const MapPoint& p, const std::array<double, 3>& offset) {
  const auto scaled = [](double v, double off) {
    return static_cast<std::int32_t>(std::llround((v - off) / kLasScale));
  };
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

MapFileWriter::MapFileWriter(const std::filesystem::path& file, MapFormat format, std::uint64_t n_points,
                             const std::array<double, 3>& las_offset, MapFileExtras extras)
    : file_(file), format_(format), n_points_(n_points), offset_(las_offset), extras_(std::move(extras)) {
  if (extras_.crs_wkt.size() >= 65535)
    throw InputError(file_.string(), "crs", fmt::format("the WKT is {} bytes: a LAS VLR holds at most 65534", extras_.crs_wkt.size()));
  out_.open(file, std::ios::binary | std::ios::trunc);
  Bytes header(kLasHeaderSize);
  switch (format_) {
    case MapFormat::ply: header.append(ply_header(n_points, extras_.ply_double)); break;
    case MapFormat::pcd: header.append(pcd_header(n_points)); break;
    case MapFormat::las: header = las_header(n_points, offset_, lo_, hi_, extras_.crs_wkt); break;
  }
  save(header.data());
}

void MapFileWriter::save(std::span<const std::uint8_t> bytes) {
  if (out_) out_.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out_) throw InputError(file_.string(), "", "cannot write the map file");
}

void MapFileWriter::write(std::span<const MapPoint> points) {
  if (points.empty()) return;
  Bytes b(points.size() * kLasPointFormat6Length);  // the largest record (PLY with doubles: 28 bytes)
  for (const MapPoint& p : points) {
    if (format_ == MapFormat::las) {
      put_las_point(b, p, offset_);
      const std::array<double, 3> v{p.x, p.y, p.z};
      for (std::size_t a = 0; a < 3; ++a) {
        lo_[a] = written_ == 0 ? v[a] : std::min(lo_[a], v[a]);
        hi_[a] = written_ == 0 ? v[a] : std::max(hi_[a], v[a]);
      }
    } else if (format_ == MapFormat::ply && extras_.ply_double) {
      put_double_xyz_float_i(b, p);
    } else {
      put_float_xyzi(b, p);
    }
    ++written_;
  }
  save(b.data());
}

void MapFileWriter::finish() {
  if (written_ != n_points_)
    throw InputError(file_.string(), "", fmt::format("{} points written, {} announced", written_, n_points_));
  if (format_ == MapFormat::las) {  // the bounds are known now
    out_.seekp(0);
    save(las_header(n_points_, offset_, lo_, hi_, extras_.crs_wkt).data());
  }
  out_.close();
  if (!out_) throw InputError(file_.string(), "", "cannot write the map file");
}

void write_map(const std::filesystem::path& file, MapFormat format, std::span<const MapPoint> points,
               const MapFileExtras& extras) {
  // Offsets at whole metres below the minimum keep the integers small and
  // positive; 1 mm scale then spans 2 147 km, far beyond any survey.
  std::array<double, 3> offset{0, 0, 0};
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::array<double, 3> v{points[i].x, points[i].y, points[i].z};
    for (std::size_t a = 0; a < 3; ++a) offset[a] = i == 0 ? v[a] : std::min(offset[a], v[a]);
  }
  for (double& o : offset) o = std::floor(o);
  MapFileWriter writer(file, format, points.size(), offset, extras);
  writer.write(points);
  writer.finish();
}

}  // namespace adit::protocol
