#include "adit/protocol/ply_mesh.hpp"

#include <cmath>
#include <fstream>
#include <iterator>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/protocol/ply_header.hpp"

namespace adit::protocol {
namespace {

// Reads scalars one after another, refusing to run past the end.
class Cursor {
 public:
  Cursor(std::string_view bytes, std::size_t offset, const std::string& name)
      : bytes_(bytes), at_(offset), name_(name) {}
  double next(std::string_view type, const char* what, std::uint64_t index) {
    const std::size_t size = ply_type_size(type);
    if (bytes_.size() - at_ < size)
      throw InputError(name_, fmt::format("{} {}", what, index), "truncated: the file ends inside it");
    const double v = read_ply_scalar(type, bytes_.data() + at_);
    at_ += size;
    return v;
  }

 private:
  std::string_view bytes_;
  std::size_t at_;
  const std::string& name_;
};

const PlyProperty* find(const PlyElement& e, std::string_view name) {
  for (const PlyProperty& p : e.properties)
    if (p.name == name) return &p;
  return nullptr;
}

}  // namespace

PlyMesh read_ply_mesh(std::string_view bytes, const std::string& name) {
  const PlyHeader header = parse_ply_header(bytes, name);
  if (header.elements.size() < 2 || header.elements[0].name != "vertex" || header.elements[1].name != "face")
    throw InputError(name, "element", "a mesh needs elements 'vertex' then 'face'");
  const PlyElement& vertex = header.elements[0];
  const PlyElement& face = header.elements[1];
  for (const PlyProperty& p : vertex.properties)
    if (!p.count_type.empty()) throw InputError(name, "property " + p.name, "list properties in 'vertex' are not read");
  const PlyProperty* indices = find(face, "vertex_indices");
  if (!indices) indices = find(face, "vertex_index");
  if (!find(vertex, "x") || !find(vertex, "y") || !find(vertex, "z") || !indices || indices->count_type.empty())
    throw InputError(name, "element", "needs vertex properties x, y, z and a face list 'vertex_indices'");

  // A count the file's size cannot hold is a lie, not a reason to allocate.
  std::size_t vertex_record = 0;
  for (const PlyProperty& p : vertex.properties) vertex_record += ply_type_size(p.type);
  std::size_t face_least = 0;  // an empty list takes only its count
  for (const PlyProperty& p : face.properties)
    face_least += ply_type_size(p.count_type.empty() ? p.type : p.count_type);
  const std::size_t room = bytes.size() - header.data_offset;
  if (vertex.count > room / vertex_record || face.count > (room - vertex.count * vertex_record) / face_least)
    throw InputError(
        name, "element",
        fmt::format("truncated: {} vertices and {} faces cannot fit in {} bytes", vertex.count, face.count, room));
  Cursor in(bytes, header.data_offset, name);
  PlyMesh mesh;
  mesh.vertices.resize(vertex.count);
  for (std::uint64_t i = 0; i < vertex.count; ++i) {
    auto& v = mesh.vertices[i];
    for (const PlyProperty& p : vertex.properties) {
      const double value = in.next(p.type, "vertex", i);
      if (p.name == "x") v[0] = value;
      if (p.name == "y") v[1] = value;
      if (p.name == "z") v[2] = value;
    }
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
      throw InputError(name, fmt::format("vertex {}", i), "non-finite coordinate");
  }
  mesh.triangles.reserve(face.count);
  std::vector<std::uint32_t> polygon;
  for (std::uint64_t i = 0; i < face.count; ++i) {
    for (const PlyProperty& p : face.properties) {
      if (p.count_type.empty()) {
        in.next(p.type, "face", i);
        continue;
      }
      const double n = in.next(p.count_type, "face", i);
      if (!(n >= 0.0 && n <= 1024.0))
        throw InputError(name, fmt::format("face {}", i), fmt::format("list of {} items", n));
      polygon.clear();
      for (int k = 0; k < static_cast<int>(n); ++k) {
        const double index = in.next(p.type, "face", i);
        if (&p != indices) continue;
        if (!(index >= 0.0 && index < static_cast<double>(vertex.count)))
          throw InputError(name, fmt::format("face {}", i),
                           fmt::format("vertex index {} of {} vertices", index, vertex.count));
        polygon.push_back(static_cast<std::uint32_t>(index));
      }
      if (&p != indices) continue;
      if (polygon.size() < 3) throw InputError(name, fmt::format("face {}", i), "fewer than 3 vertices");
      // A convex polygon as a fan of triangles from its first vertex.
      for (std::size_t k = 1; k + 1 < polygon.size(); ++k)
        mesh.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
    }
  }
  return mesh;
}

PlyMesh read_ply_mesh(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot open the mesh file");
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return read_ply_mesh(bytes, file.string());
}

}  // namespace adit::protocol
