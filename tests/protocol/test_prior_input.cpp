// Prior map sources: OBJ and STL meshes (ASCII and binary), mesh sampling at
// a set density, units, axes and offset, and the errors for bad files.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "adit/common/error.hpp"
#include "adit/protocol/mesh_files.hpp"
#include "adit/protocol/prior_input.hpp"

namespace adit::protocol {
namespace {

// A 2 m x 3 m quad at z = 0 as OBJ (a polygon: split into two triangles).
constexpr const char* kQuadObj = "# a floor\nv 0 0 0\nv 2 0 0\nv 2 3 0\nv 0 3 0\nvn 0 0 1\nf 1//1 2//1 3//1 -1//1\n";

std::filesystem::path write_file(const std::string& name, const std::string& bytes) {
  const auto path = std::filesystem::temp_directory_path() / ("adit_prior_input_" + name);
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

std::string binary_stl(int facets) {
  std::string b(80, ' ');
  const auto n = static_cast<std::uint32_t>(facets);
  b.append(reinterpret_cast<const char*>(&n), 4);
  for (int f = 0; f < facets; ++f) {
    const float v[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};  // normal, then a right triangle of area 0.5 at z = 0
    b.append(reinterpret_cast<const char*>(v), sizeof v);
    b.append(2, '\0');
  }
  return b;
}

TEST(MeshFiles, ObjPolygonsBecomeFans) {
  const PlyMesh mesh = read_obj_mesh(kQuadObj, "quad.obj");
  EXPECT_EQ(mesh.vertices.size(), 4U);
  ASSERT_EQ(mesh.triangles.size(), 2U);
  EXPECT_EQ(mesh.triangles[1][2], 3U);  // -1 is the last vertex
}

TEST(MeshFiles, ObjErrorsNameTheLine) {
  try {
    read_obj_mesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", "bad.obj");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.obj:4"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_obj_mesh("v 0 0 x\n", "bad.obj"), InputError);
  EXPECT_THROW(read_obj_mesh("v 0 0 0\n", "points.obj"), InputError);  // no faces
}

TEST(MeshFiles, StlBinaryAndAscii) {
  EXPECT_EQ(read_stl_mesh(binary_stl(3), "b.stl").triangles.size(), 3U);
  const std::string ascii =
      "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
  EXPECT_EQ(read_stl_mesh(ascii, "a.stl").triangles.size(), 1U);
  EXPECT_THROW(read_stl_mesh(binary_stl(3).substr(0, 150), "cut.stl"), InputError);
  EXPECT_THROW(read_stl_mesh("solid t\nfacet\nouter loop\nvertex 0 0 0\nendloop\n", "a.stl"), InputError);
}

TEST(PriorInput, MeshSampledAtTheDensity) {
  const auto path = write_file("quad.obj", kQuadObj);
  PriorInputOptions o;
  o.mesh_points_per_m2 = 1000.0;
  const PriorInput in = read_prior_input(path, o);
  EXPECT_TRUE(in.mesh);
  EXPECT_NEAR(in.area_m2, 6.0, 1e-9);
  EXPECT_NEAR(static_cast<double>(in.points.size()), 6000.0, 150.0);
  for (const auto& p : in.points) {
    EXPECT_GE(p[0], 0.0F);
    EXPECT_LE(p[0], 2.0F);
    EXPECT_GE(p[1], 0.0F);
    EXPECT_LE(p[1], 3.0F);
    EXPECT_EQ(p[2], 0.0F);
  }
  EXPECT_EQ(read_prior_input(path, o).points, in.points);  // same seed, same points
}

TEST(PriorInput, ScaleAxesAndOffset) {
  // The quad in millimetres, Y-up, in a site frame 500 km east.
  const auto path = write_file("quad_mm.obj", "v 500000000 0 0\nv 500002000 0 0\nv 500002000 0 -3000\nf 1 2 3\n");
  PriorInputOptions o;
  o.scale = 0.001;
  o.y_up = true;
  o.offset = {500000.0, 0.0, 0.0};
  const PriorInput in = read_prior_input(path, o);
  for (const auto& p : in.points) {
    EXPECT_GE(p[0], -1e-3F);
    EXPECT_LE(p[0], 2.001F);
    EXPECT_GE(p[1], -1e-3F);  // -z became +y
    EXPECT_NEAR(p[2], 0.0F, 1e-6F);
  }
  // Without the offset the site frame is refused (floats would lose the centimetres).
  o.offset = {0.0, 0.0, 0.0};
  EXPECT_THROW(read_prior_input(path, o), InputError);
}

TEST(PriorInput, BadFilesAreRefusedByName) {
  EXPECT_THROW(read_prior_input(write_file("empty.ply", "")), InputError);
  EXPECT_THROW(read_prior_input("/nonexistent/prior.ply"), InputError);
  try {
    read_prior_input(write_file("model.ifc", "ISO-10303-21;\n"));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("IFC"), std::string::npos) << e.what();
  }
  PriorInputOptions o;
  o.max_points = 100;  // a "huge" file, scaled down
  EXPECT_THROW(read_prior_input(write_file("big.obj", kQuadObj), o), InputError);
}

}  // namespace
}  // namespace adit::protocol
