#pragma once
// Reading map files back: the PLY, PCD and LAS files write_map makes, and
// files of the same families from other tools when the layout is a plain one
// (PLY binary little-endian with scalar vertex properties x y z [intensity];
// PCD "DATA binary" with fields x y z [intensity]; LAS 1.0-1.4, point data
// record formats 0-10, uncompressed). Anything else, or a truncated file,
// throws adit::InputError naming the file and what is wrong.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "adit/protocol/map_export.hpp"
#include "adit/protocol/map_point.hpp"

namespace adit::protocol {

// The format from the extension (.ply, .pcd, .las; any case).
MapFormat map_format_of(const std::filesystem::path& file);

std::vector<MapPoint> read_map(const std::filesystem::path& file);

// The same from the file's bytes; `name` is the file named in errors.
std::vector<MapPoint> read_map(std::string_view bytes, MapFormat format, const std::string& name);

}  // namespace adit::protocol
