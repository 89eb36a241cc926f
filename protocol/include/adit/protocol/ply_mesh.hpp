#pragma once
// A triangle mesh from a binary little-endian PLY file: the simulator's
// scene.ply (float x y z; faces as 'list uchar uint vertex_indices' plus a
// reflectivity byte), or the same layout with other scalar types, extra
// scalar properties (skipped) and polygons (split into fans). Elements must
// be 'vertex' then 'face'; any after them are ignored. Bad, truncated or
// out-of-range data throws adit::InputError naming the file.

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace adit::protocol {

struct PlyMesh {
  std::vector<std::array<double, 3>> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;  // indices into vertices
};

PlyMesh read_ply_mesh(const std::filesystem::path& file);
PlyMesh read_ply_mesh(std::string_view bytes, const std::string& name);

}  // namespace adit::protocol
