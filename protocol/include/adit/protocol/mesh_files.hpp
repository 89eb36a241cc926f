#pragma once
// Triangle meshes from the files BIM and CAD tools export besides PLY:
// Wavefront OBJ (text: `v x y z`, `f a b c ...` with 1-based or negative
// indices, `a/t/n` forms; polygons split into fans; other statements skipped)
// and STL (binary: an 80-byte header, a count, 50-byte facets; or ASCII
// `solid ... facet ... vertex x y z`). Each returns the PlyMesh of
// read_ply_mesh. Bad, truncated or out-of-range data throws adit::InputError
// naming the file and the line (OBJ, ASCII STL) or the facet (binary STL).

#include <filesystem>
#include <string>
#include <string_view>

#include "adit/protocol/ply_mesh.hpp"

namespace adit::protocol {

PlyMesh read_obj_mesh(std::string_view bytes, const std::string& name);
PlyMesh read_stl_mesh(std::string_view bytes, const std::string& name);

// By the extension: .ply (with faces), .obj or .stl (any case).
PlyMesh read_mesh_file(const std::filesystem::path& file);

}  // namespace adit::protocol
