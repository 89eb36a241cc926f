#include "adit/protocol/mesh_files.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::protocol {
namespace {

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

// Splits on blanks (spaces, tabs).
std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

double number(std::string_view w, const std::string& name, std::size_t line) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(w.data(), w.data() + w.size(), v);
  if (ec != std::errc{} || end != w.data() + w.size() || !std::isfinite(v))
    throw InputError(fmt::format("{}:{}", name, line), "", fmt::format("'{}' is not a finite number", w));
  return v;
}

template <typename Line>
void for_each_line(std::string_view bytes, Line&& on_line) {
  std::size_t at = 0, number = 0;
  while (at < bytes.size()) {
    std::size_t end = bytes.find('\n', at);
    if (end == std::string_view::npos) end = bytes.size();
    on_line(trim(bytes.substr(at, end - at)), ++number);
    at = end + 1;
  }
}

std::string read_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot be read");
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

PlyMesh read_obj_mesh(std::string_view bytes, const std::string& name) {
  PlyMesh mesh;
  std::vector<std::uint32_t> face;
  for_each_line(bytes, [&](std::string_view line, std::size_t n) {
    if (line.empty() || line[0] == '#') return;
    const std::vector<std::string_view> w = words(line);
    if (w[0] == "v") {
      if (w.size() < 4) throw InputError(fmt::format("{}:{}", name, n), "v", "a vertex needs x y z");
      mesh.vertices.push_back({number(w[1], name, n), number(w[2], name, n), number(w[3], name, n)});
    } else if (w[0] == "f") {
      if (w.size() < 4) throw InputError(fmt::format("{}:{}", name, n), "f", "a face needs at least 3 vertices");
      face.clear();
      for (std::size_t k = 1; k < w.size(); ++k) {
        const std::string_view index_text = w[k].substr(0, w[k].find('/'));
        long long index = 0;
        const auto [end, ec] = std::from_chars(index_text.data(), index_text.data() + index_text.size(), index);
        if (ec != std::errc{} || end != index_text.data() + index_text.size() || index == 0)
          throw InputError(fmt::format("{}:{}", name, n), "f", fmt::format("'{}' is not a vertex index", w[k]));
        // 1-based; negative counts back from the last vertex read.
        const long long count = static_cast<long long>(mesh.vertices.size());
        const long long resolved = index > 0 ? index - 1 : count + index;
        if (resolved < 0 || resolved >= count)
          throw InputError(fmt::format("{}:{}", name, n), "f",
                           fmt::format("vertex {} does not exist ({} read so far)", index, count));
        face.push_back(static_cast<std::uint32_t>(resolved));
      }
      for (std::size_t k = 1; k + 1 < face.size(); ++k) mesh.triangles.push_back({face[0], face[k], face[k + 1]});
    }
  });
  if (mesh.triangles.empty()) throw InputError(name, "f", "no faces: not a mesh (a point cloud? give it as PLY, PCD or LAS)");
  return mesh;
}

PlyMesh read_stl_mesh(std::string_view bytes, const std::string& name) {
  PlyMesh mesh;
  // Binary when the facet count matches the length (an ASCII file may start with "solid" too, and some binary ones do).
  if (bytes.size() >= 84) {
    std::uint32_t count = 0;
    std::memcpy(&count, bytes.data() + 80, 4);
    if (84 + 50 * static_cast<std::uint64_t>(count) == bytes.size()) {
      mesh.vertices.reserve(3 * static_cast<std::size_t>(count));
      for (std::uint32_t f = 0; f < count; ++f) {
        const char* facet = bytes.data() + 84 + 50 * static_cast<std::size_t>(f);
        for (int v = 0; v < 3; ++v) {
          std::array<float, 3> xyz{};
          std::memcpy(xyz.data(), facet + 12 + 12 * v, 12);
          if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2]))
            throw InputError(name, fmt::format("facet {}", f), "a vertex is not finite");
          mesh.vertices.push_back({xyz[0], xyz[1], xyz[2]});
        }
        const auto base = static_cast<std::uint32_t>(3 * f);
        mesh.triangles.push_back({base, base + 1, base + 2});
      }
      if (mesh.triangles.empty()) throw InputError(name, "", "no facets");
      return mesh;
    }
  }
  if (bytes.substr(0, std::min<std::size_t>(bytes.size(), 5)) != "solid")
    throw InputError(name, "", "neither binary STL (84 + 50 x facets bytes) nor ASCII STL ('solid ...')");
  int in_facet = 0;
  for_each_line(bytes, [&](std::string_view line, std::size_t n) {
    const std::vector<std::string_view> w = words(line);
    if (w.empty()) return;
    if (w[0] == "vertex") {
      if (w.size() != 4) throw InputError(fmt::format("{}:{}", name, n), "vertex", "needs x y z");
      mesh.vertices.push_back({number(w[1], name, n), number(w[2], name, n), number(w[3], name, n)});
      ++in_facet;
    } else if (w[0] == "endloop") {
      if (in_facet != 3) throw InputError(fmt::format("{}:{}", name, n), "endloop", fmt::format("{} vertices, not 3", in_facet));
      const auto base = static_cast<std::uint32_t>(mesh.vertices.size() - 3);
      mesh.triangles.push_back({base, base + 1, base + 2});
      in_facet = 0;
    }
  });
  if (mesh.triangles.empty()) throw InputError(name, "", "no facets");
  return mesh;
}

PlyMesh read_mesh_file(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".ply") return read_ply_mesh(file);
  const std::string bytes = read_file(file);
  if (ext == ".obj") return read_obj_mesh(bytes, file.string());
  if (ext == ".stl") return read_stl_mesh(bytes, file.string());
  throw InputError(file.string(), "", "unknown mesh format (give .ply, .obj or .stl)");
}

}  // namespace adit::protocol
