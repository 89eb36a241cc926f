#pragma once
// A prior map's source file as points: a point cloud (PLY vertices only, PCD,
// LAS: read_map) or a mesh (PLY with faces, OBJ, STL: sampled uniformly on
// its surface at a set density, so a wall's share of the points is its share
// of the area, as a scan sees it). Coordinates are scaled (0.001 for a file
// in millimetres), rotated Y-up to Z-up when asked, then the offset is
// subtracted in double precision before they become floats (a site frame's
// coordinates, UTM or a building grid, are large: floats keep 1 cm only below
// ~100 km, 1 mm below ~8 km). Throws adit::InputError naming the file: empty,
// larger than max_points, or coordinates still beyond 20 km after the offset.

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace adit::protocol {

struct PriorInputOptions {
  double mesh_points_per_m2 = 400.0;            // a sample every 5 cm on a mesh's surfaces
  double scale = 1.0;                           // multiplies the file's coordinates (0.001: millimetres)
  bool y_up = false;                            // the file's up axis is y (many CAD exports): (x, y, z) -> (x, -z, y)
  std::array<double, 3> offset{0.0, 0.0, 0.0};  // subtracted after scaling: the local frame's origin in the site frame
  std::size_t max_points = 100'000'000;         // more (read or to sample): refused, crop or lower the density
  std::uint64_t seed = 1;                       // of the mesh sampling (same seed, same points)
};

struct PriorInput {
  std::vector<std::array<float, 3>> points;
  bool mesh = false;            // sampled from a mesh
  std::size_t triangles = 0;    // of the mesh
  double area_m2 = 0.0;         // of the mesh, after scaling
};

PriorInput read_prior_input(const std::filesystem::path& file, const PriorInputOptions& options = {});

}  // namespace adit::protocol
