#include "adit/sim/mesh.hpp"

#include <fstream>
#include <string>

#include "adit/common/error.hpp"

namespace adit::sim {

void TriangleMesh::add_quad(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                            const Eigen::Vector3f& d, std::uint8_t reflect) {
  const auto i = static_cast<std::uint32_t>(vertices.size());
  vertices.insert(vertices.end(), {a, b, c, d});
  triangles.push_back({i, i + 1, i + 2});
  triangles.push_back({i, i + 2, i + 3});
  reflectivity.insert(reflectivity.end(), 2, reflect);
}

void TriangleMesh::append(const TriangleMesh& other) {
  const auto base = static_cast<std::uint32_t>(vertices.size());
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  for (const auto& t : other.triangles) triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  reflectivity.insert(reflectivity.end(), other.reflectivity.begin(), other.reflectivity.end());
}

namespace {

void check(const std::ofstream& out, const std::filesystem::path& file) {
  if (!out) throw InputError(file.string(), "", "could not write the PLY file");
}

}  // namespace

void write_ply(const std::filesystem::path& file, const TriangleMesh& mesh) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  check(out, file);
  out << "ply\nformat binary_little_endian 1.0\ncomment adit sim scene\nelement vertex " << mesh.vertices.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << mesh.triangles.size()
      << "\nproperty list uchar uint vertex_indices\nproperty uchar reflectivity\nend_header\n";
  // x86 and ARM payload computers are little-endian, as the format says.
  for (const auto& v : mesh.vertices) out.write(reinterpret_cast<const char*>(v.data()), 3 * sizeof(float));
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const char n = 3;
    out.write(&n, 1);
    out.write(reinterpret_cast<const char*>(mesh.triangles[i].data()), 3 * sizeof(std::uint32_t));
    out.write(reinterpret_cast<const char*>(&mesh.reflectivity[i]), 1);
  }
  check(out, file);
}

void write_ply_points(const std::filesystem::path& file, const std::vector<Eigen::Vector3f>& points) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  check(out, file);
  out << "ply\nformat binary_little_endian 1.0\ncomment adit sim\nelement vertex " << points.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (const auto& v : points) out.write(reinterpret_cast<const char*>(v.data()), 3 * sizeof(float));
  check(out, file);
}

}  // namespace adit::sim
