#pragma once
// A scene as a triangle soup with a reflectivity per triangle (0-100 diffuse,
// as the Velodyne manual's calibrated reflectivity scale, §6.3).

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include <Eigen/Core>

namespace adit::sim {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<std::uint8_t> reflectivity;  // per triangle

  // Two triangles a-b-c, a-c-d.
  void add_quad(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c, const Eigen::Vector3f& d,
                std::uint8_t reflect);
  // A closed axis-aligned box (furniture, obstacles).
  void add_box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, std::uint8_t reflect);
  void append(const TriangleMesh& other);
};

// Binary little-endian PLY: vertices (float x, y, z) and faces (uchar count, uint indices).
// Point-cloud tools read the vertices, mesh tools the faces. Throws adit::InputError on I/O failure.
void write_ply(const std::filesystem::path& file, const TriangleMesh& mesh);
// Points spread uniformly over the surfaces, `per_m2` on average, deterministic
// for the seed (the BIM prior map's cloud).
std::vector<Eigen::Vector3f> sample_surface(const TriangleMesh& mesh, double per_m2, std::uint64_t seed);

// Binary little-endian PLY with vertices only.
void write_ply_points(const std::filesystem::path& file, const std::vector<Eigen::Vector3f>& points);

}  // namespace adit::sim
