#include "adit/sim/mesh.hpp"

#include <fstream>
#include <string>

#include <Eigen/Geometry>

#include "adit/common/error.hpp"
#include "adit/sim/hash_noise.hpp"

namespace adit::sim {

void TriangleMesh::add_quad(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                            const Eigen::Vector3f& d, std::uint8_t reflect) {
  const auto i = static_cast<std::uint32_t>(vertices.size());
  vertices.insert(vertices.end(), {a, b, c, d});
  triangles.push_back({i, i + 1, i + 2});
  triangles.push_back({i, i + 2, i + 3});
  reflectivity.insert(reflectivity.end(), 2, reflect);
}

void TriangleMesh::add_box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, std::uint8_t reflect) {
  const auto v = [&](int x, int y, int z) {
    return Eigen::Vector3f(x ? hi.x() : lo.x(), y ? hi.y() : lo.y(), z ? hi.z() : lo.z());
  };
  add_quad(v(0, 0, 0), v(1, 0, 0), v(1, 1, 0), v(0, 1, 0), reflect);  // bottom
  add_quad(v(0, 0, 1), v(0, 1, 1), v(1, 1, 1), v(1, 0, 1), reflect);  // top
  add_quad(v(0, 0, 0), v(0, 0, 1), v(1, 0, 1), v(1, 0, 0), reflect);
  add_quad(v(0, 1, 0), v(1, 1, 0), v(1, 1, 1), v(0, 1, 1), reflect);
  add_quad(v(0, 0, 0), v(0, 1, 0), v(0, 1, 1), v(0, 0, 1), reflect);
  add_quad(v(1, 0, 0), v(1, 0, 1), v(1, 1, 1), v(1, 1, 0), reflect);
}

std::vector<Eigen::Vector3f> sample_surface(const TriangleMesh& mesh, double per_m2, std::uint64_t seed) {
  std::vector<Eigen::Vector3f> points;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3d a = mesh.vertices[mesh.triangles[t][0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[mesh.triangles[t][1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[mesh.triangles[t][2]].cast<double>();
    const double expected = 0.5 * (b - a).cross(c - a).norm() * per_m2;
    // Whole points, plus one more with the probability of the fraction.
    auto n = static_cast<std::uint64_t>(expected);
    if (uniform(seed, 0x4E756DULL, t) < expected - static_cast<double>(n)) ++n;
    for (std::uint64_t k = 0; k < n; ++k) {
      // Uniform on the triangle (Osada et al. 2002): reflect the unit square's upper half.
      double u = uniform(seed, 0x5531ULL + t, 2 * k), v = uniform(seed, 0x5531ULL + t, 2 * k + 1);
      if (u + v > 1.0) {
        u = 1.0 - u;
        v = 1.0 - v;
      }
      points.push_back((a + u * (b - a) + v * (c - a)).cast<float>());
    }
  }
  return points;
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
