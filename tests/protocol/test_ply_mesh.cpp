// Triangle meshes in the simulator's scene.ply layout, written here byte by
// byte, read by read_ply_mesh.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "adit/common/error.hpp"
#include "adit/protocol/ply_mesh.hpp"

namespace adit::protocol {
namespace {

template <typename T>
void put(std::string& bytes, T v) {
  bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// Two triangles of the unit square at z = 1, as sim's write_ply writes them.
std::string scene_bytes(std::uint32_t last_index = 3) {
  std::string b =
      "ply\nformat binary_little_endian 1.0\ncomment adit sim scene\nelement vertex 4\nproperty float x\n"
      "property float y\nproperty float z\nelement face 2\nproperty list uchar uint vertex_indices\n"
      "property uchar reflectivity\nend_header\n";
  for (const auto& v : {std::array<float, 3>{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}})
    for (float c : v) put(b, c);
  for (const auto& t : {std::array<std::uint32_t, 3>{0, 1, 2}, {0, 2, last_index}}) {
    put<std::uint8_t>(b, 3);
    for (auto i : t) put(b, i);
    put<std::uint8_t>(b, 40);
  }
  return b;
}

std::string error_key(const std::string& bytes) {
  try {
    read_ply_mesh(bytes, "scene.ply");
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().rfind("scene.ply", 0), 0u) << e.where();
    return e.key().empty() ? "(none)" : e.key();
  }
  return "";
}

TEST(PlyMesh, ReadsTheSimulatorsLayout) {
  const PlyMesh mesh = read_ply_mesh(scene_bytes(), "scene.ply");
  ASSERT_EQ(mesh.vertices.size(), 4u);
  ASSERT_EQ(mesh.triangles.size(), 2u);
  EXPECT_EQ(mesh.vertices[2], (std::array<double, 3>{1, 1, 1}));
  EXPECT_EQ(mesh.triangles[1], (std::array<std::uint32_t, 3>{0, 2, 3}));
}

TEST(PlyMesh, PolygonsBecomeFans) {
  std::string b =
      "ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty double x\nproperty double y\n"
      "property double z\nelement face 1\nproperty list uchar int vertex_index\nend_header\n";
  for (int i = 0; i < 5; ++i) put(b, double(i)), put(b, double(i * i)), put(b, 0.0);
  put<std::uint8_t>(b, 5);
  for (int i = 0; i < 5; ++i) put(b, 4 - i);
  const PlyMesh mesh = read_ply_mesh(b, "scene.ply");
  ASSERT_EQ(mesh.triangles.size(), 3u);
  EXPECT_EQ(mesh.triangles[2], (std::array<std::uint32_t, 3>{4, 1, 0}));
  EXPECT_EQ(mesh.vertices[3][1], 9.0);
}

TEST(PlyMesh, BadMeshesAreNamed) {
  EXPECT_EQ(error_key(scene_bytes(4)), "face 1");  // index past the 4 vertices
  const std::string good = scene_bytes();
  EXPECT_EQ(error_key(good.substr(0, good.size() - 3)), "face 1");                     // truncated inside the last face
  EXPECT_EQ(error_key(good.substr(0, good.find("end_header") + 11 + 20)), "element");  // counts cannot fit
  std::string no_faces = good;
  no_faces.replace(no_faces.find("element face 2"), 14, "element edge 2");
  EXPECT_EQ(error_key(no_faces), "element");
  EXPECT_EQ(error_key("ply\nformat ascii 1.0\nend_header\n"), "(none)");
  EXPECT_EQ(error_key("solid stl\n"), "(none)");
}

}  // namespace
}  // namespace adit::protocol
