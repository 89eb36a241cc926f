#include "adit/protocol/prior_input.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/protocol/map_import.hpp"
#include "adit/protocol/mesh_files.hpp"
#include "adit/protocol/ply_header.hpp"

namespace adit::protocol {
namespace {

using Vec = std::array<double, 3>;

std::string lower_extension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// A PLY holding faces is a mesh; one with vertices only a point cloud.
bool ply_has_faces(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot be read");
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (head.find("end_header") == std::string::npos) return false;  // read_map names the problem
  const PlyHeader header = parse_ply_header(head, file.string());
  return std::any_of(header.elements.begin(), header.elements.end(),
                     [](const PlyElement& e) { return e.name == "face" && e.count > 0; });
}

Vec transform(Vec p, const PriorInputOptions& o) {
  for (double& v : p) v *= o.scale;
  if (o.y_up) p = {p[0], -p[2], p[1]};
  return {p[0] - o.offset[0], p[1] - o.offset[1], p[2] - o.offset[2]};
}

// splitmix64 (Steele, Lea & Flood 2014): a counter-based draw, so the samples do not depend on the order of work.
double uniform(std::uint64_t seed, std::uint64_t counter) {
  std::uint64_t z = seed * 0x9E3779B97F4A7C15ULL + counter + 0x632BE59BD9B4E019ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53;
}

void add_point(PriorInput& out, const Vec& p, const std::string& name) {
  for (const double v : p)
    if (!std::isfinite(v) || std::abs(v) > 20000.0)
      throw InputError(name, "", fmt::format("a point lies at ({:.1f}, {:.1f}, {:.1f}) m after scaling and offset: beyond "
                                             "20 km (millimetres? give --scale 0.001; a site frame? give --offset)",
                                             p[0], p[1], p[2]));
  out.points.push_back({static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])});
}

PriorInput sample_mesh(const PlyMesh& mesh, const PriorInputOptions& o, const std::string& name) {
  PriorInput out;
  out.mesh = true;
  out.triangles = mesh.triangles.size();
  std::vector<Vec> v(mesh.vertices.size());
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = transform(mesh.vertices[i], o);
  std::vector<double> areas(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Vec& a = v[mesh.triangles[t][0]];
    const Vec& b = v[mesh.triangles[t][1]];
    const Vec& c = v[mesh.triangles[t][2]];
    const Vec ab{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ac{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const Vec x{ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0]};
    areas[t] = 0.5 * std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    out.area_m2 += areas[t];
  }
  const double expected = out.area_m2 * o.mesh_points_per_m2;
  if (expected > static_cast<double>(o.max_points))
    throw InputError(name, "", fmt::format("{:.0f} m² of surface at {:.0f} points/m² makes {:.0f} points, more than {}: "
                                           "lower the density (millimetres read as metres? give --scale 0.001)",
                                           out.area_m2, o.mesh_points_per_m2, expected, o.max_points));
  out.points.reserve(static_cast<std::size_t>(expected * 1.01) + 16);
  std::uint64_t draw = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    // floor(expected) points, one more with the fraction's probability: unbiased per triangle.
    const double want = areas[t] * o.mesh_points_per_m2;
    const auto n = static_cast<std::size_t>(want) + (uniform(o.seed, draw++) < want - std::floor(want) ? 1U : 0U);
    const Vec& a = v[mesh.triangles[t][0]];
    const Vec& b = v[mesh.triangles[t][1]];
    const Vec& c = v[mesh.triangles[t][2]];
    for (std::size_t k = 0; k < n; ++k) {
      // Uniform on the triangle: Osada et al. (2002), §4.2.
      const double r1 = std::sqrt(uniform(o.seed, draw++)), r2 = uniform(o.seed, draw++);
      const double wa = 1.0 - r1, wb = r1 * (1.0 - r2), wc = r1 * r2;
      add_point(out, {wa * a[0] + wb * b[0] + wc * c[0], wa * a[1] + wb * b[1] + wc * c[1], wa * a[2] + wb * b[2] + wc * c[2]},
                name);
    }
  }
  return out;
}

}  // namespace

PriorInput read_prior_input(const std::filesystem::path& file, const PriorInputOptions& options) {
  if (!(options.scale > 0.0) || !std::isfinite(options.scale)) throw InputError(file.string(), "scale", "must be > 0");
  const std::string name = file.string();
  if (!std::filesystem::is_regular_file(file)) throw InputError(name, "", "no such file");
  if (std::filesystem::file_size(file) == 0) throw InputError(name, "", "empty file");
  const std::string ext = lower_extension(file);
  PriorInput out;
  if (ext == ".obj" || ext == ".stl" || (ext == ".ply" && ply_has_faces(file))) {
    out = sample_mesh(read_mesh_file(file), options, name);
  } else if (ext == ".ply" || ext == ".pcd" || ext == ".las") {
    const std::vector<MapPoint> points = read_map(file);
    if (points.size() > options.max_points)
      throw InputError(name, "", fmt::format("{} points, more than {}: crop or downsample it first", points.size(), options.max_points));
    out.points.reserve(points.size());
    for (const MapPoint& p : points) add_point(out, transform({p.x, p.y, p.z}, options), name);
  } else if (ext == ".ifc") {
    throw InputError(name, "", "IFC is not read directly: export the model's surfaces as OBJ, STL or PLY "
                               "(docs/PRIOR-MAP.md: IfcConvert, FreeCAD, BlenderBIM)");
  } else {
    throw InputError(name, "", "unknown prior format (point clouds: .ply .pcd .las; meshes: .ply .obj .stl)");
  }
  if (out.points.empty()) throw InputError(name, "", "no points (an empty cloud, or a mesh of zero area)");
  return out;
}

}  // namespace adit::protocol
