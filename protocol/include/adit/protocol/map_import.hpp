#pragma once
// Reading map files back: the PLY, PCD and LAS files write_map makes, and
// files of the same families from other tools when the layout is a plain one
// (PLY binary little-endian with scalar vertex properties x y z [intensity];
// PCD "DATA binary" with fields x y z [intensity]; LAS 1.0-1.4, point data
// record formats 0-10, uncompressed). Anything else, or a truncated file,
// throws adit::InputError naming the file and what is wrong.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "adit/protocol/map_export.hpp"
#include "adit/protocol/map_point.hpp"

namespace adit::protocol {

// The format from the extension (.ply, .pcd, .las; any case).
MapFormat map_format_of(const std::filesystem::path& file);

std::vector<MapPoint> read_map(const std::filesystem::path& file);

// A map file read a block of points at a time, so that a caller that keeps
// only some of them (products::thin_to_voxels on a 14.7 M-point map) does not
// hold the whole file nor every point: memory for one block (64 Ki points).
// The header is read and checked against the file's size on construction.
class MapFileReader {
 public:
  explicit MapFileReader(const std::filesystem::path& file);
  ~MapFileReader();
  MapFileReader(const MapFileReader&) = delete;
  MapFileReader& operator=(const MapFileReader&) = delete;

  std::uint64_t count() const;  // the points the header announces
  // The next points in file order; empty at the end. Valid until the next call.
  std::span<const MapPoint> next();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The same from the file's bytes; `name` is the file named in errors.
std::vector<MapPoint> read_map(std::string_view bytes, MapFormat format, const std::string& name);

}  // namespace adit::protocol
