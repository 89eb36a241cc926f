#pragma once
// Map files for operators: binary PLY (CloudCompare, MeshLab), binary PCD
// (PCL) and LAS 1.4 point data record format 6 (every survey package), all
// written by hand: Debian has no LAS library.

#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "adit/protocol/map_point.hpp"

namespace adit::protocol {

enum class MapFormat { ply, pcd, las };
std::optional<MapFormat> parse_map_format(std::string_view name);

// What a map in site coordinates (E ~ 500 000 m, N ~ 7 000 000 m) needs
// beyond a map in the session's own frame (`adit georef`).
struct MapFileExtras {
  // LAS: the coordinate reference system as OGC WKT (LAS 1.4 R15 "Georeferencing
  // Information Using WKT"): one VLR "LASF_Projection" / record 2112 holding it
  // NUL-terminated; global encoding bit 4 (WKT) is set for format 6 anyway.
  std::string crs_wkt;
  // PLY: x, y, z as doubles; a float keeps only ~0.5 m at N = 7 000 000.
  bool ply_double = false;
};

// Throws adit::InputError naming the file when it cannot be written.
void write_map(const std::filesystem::path& file, MapFormat format, std::span<const MapPoint> points,
               const MapFileExtras& extras = {});

// Writes a map file a batch of points at a time, so that a large map never has
// to be in memory whole (a session's stop-time export goes tile by tile). The
// point count must be known up front: every format's header gives it. LAS
// stores points as integers from `las_offset` (whole metres at or below the
// map's minimum keep them small and positive); its bounds are written by
// finish(). Throws adit::InputError naming the file when it cannot be written.
class MapFileWriter {
 public:
  MapFileWriter(const std::filesystem::path& file, MapFormat format, std::uint64_t n_points,
                const std::array<double, 3>& las_offset = {0, 0, 0}, MapFileExtras extras = {});
  void write(std::span<const MapPoint> points);
  // Throws when the count written differs from the one announced.
  void finish();

 private:
  void save(std::span<const std::uint8_t> bytes);
  std::filesystem::path file_;
  MapFormat format_;
  std::uint64_t n_points_;
  std::uint64_t written_ = 0;
  std::array<double, 3> offset_;
  MapFileExtras extras_;
  std::array<double, 3> lo_{0, 0, 0};
  std::array<double, 3> hi_{0, 0, 0};
  std::ofstream out_;
};

// LAS 1.4 R15 constants the writer uses (and the tests check against).
inline constexpr std::size_t kLasHeaderSize = 375;
inline constexpr std::size_t kLasPointFormat6Length = 30;
inline constexpr std::size_t kLasVlrHeaderSize = 54;
inline constexpr std::uint16_t kLasWktRecordId = 2112;  // "LASF_Projection": OGC coordinate system WKT
inline constexpr double kLasScale = 0.001;  // 1 mm, like the tile quantum
// Seconds from the Unix epoch to the GPS epoch (1980-01-06) and GPS - UTC leap
// seconds since 2017; Adjusted Standard GPS Time is GPS seconds - 1e9.
inline constexpr double kGpsEpochUnixSeconds = 315964800.0;
inline constexpr double kGpsLeapSeconds = 18.0;
double adjusted_standard_gps_time(double unix_seconds);

}  // namespace adit::protocol
