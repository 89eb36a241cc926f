#include "adit/sim/plan_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "adit/sim/hash_noise.hpp"

namespace adit::sim {
namespace {

constexpr double kBelowFloor = 0.3;  // walls reach this far below the floor and above the roof
constexpr int kWallRows = 12;

struct Grid {
  Eigen::Vector2d origin;
  double cell = 0.25;
  int nx = 0, ny = 0;  // nodes
  std::vector<double> d;
  double at(int i, int j) const { return d[static_cast<std::size_t>(j) * nx + i]; }
  Eigen::Vector2d node(int i, int j) const { return origin + cell * Eigen::Vector2d(i, j); }
};

Grid distance_grid(const Plan& plan, double cell) {
  Eigen::Vector2d lo(1e30, 1e30), hi(-1e30, -1e30);
  const auto grow = [&](const Eigen::Vector2d& p, double r) {
    lo = lo.cwiseMin(p - Eigen::Vector2d(r, r));
    hi = hi.cwiseMax(p + Eigen::Vector2d(r, r));
  };
  for (const Drift& s : plan.drifts) {
    grow(s.a, s.width_m);
    grow(s.b, s.width_m);
  }
  for (const Chamber& c : plan.chambers) grow(c.centre, c.radius_m + 1.0);
  for (const Box2& r : plan.rooms) {
    grow(r.lo, 0.5);
    grow(r.hi, 0.5);
  }
  Grid g;
  g.cell = cell;
  g.origin = (lo / cell).array().floor().matrix() * cell - Eigen::Vector2d(2.0, 2.0);
  g.nx = static_cast<int>(std::ceil((hi.x() - g.origin.x()) / cell)) + 9;
  g.ny = static_cast<int>(std::ceil((hi.y() - g.origin.y()) / cell)) + 9;
  g.d.resize(static_cast<std::size_t>(g.nx) * g.ny);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) g.d[static_cast<std::size_t>(j) * g.nx + i] = plan.distance(g.node(i, j));
  return g;
}

// The boundary crossing on the grid edge between two nodes, computed from the
// lower-indexed node so both cells sharing the edge get the same point.
Eigen::Vector2d crossing(const Grid& g, int i0, int j0, int i1, int j1) {
  if (j1 < j0 || (j1 == j0 && i1 < i0)) {
    std::swap(i0, i1);
    std::swap(j0, j1);
  }
  const double d0 = g.at(i0, j0), d1 = g.at(i1, j1);
  const double t = d0 / (d0 - d1);
  return g.node(i0, j0) + t * (g.node(i1, j1) - g.node(i0, j0));
}

Eigen::Vector2d outward_normal(const Plan& plan, const Eigen::Vector2d& p) {
  constexpr double h = 0.02;
  const Eigen::Vector2d gradient(plan.distance(p + Eigen::Vector2d(h, 0)) - plan.distance(p - Eigen::Vector2d(h, 0)),
                                 plan.distance(p + Eigen::Vector2d(0, h)) - plan.distance(p - Eigen::Vector2d(0, h)));
  const double n = gradient.norm();
  return n > 0 ? Eigen::Vector2d(gradient / n) : Eigen::Vector2d(1, 0);
}

void add_wall(const Plan& plan, const Eigen::Vector2d& a, const Eigen::Vector2d& b, TriangleMesh& mesh) {
  const Eigen::Vector2d na = outward_normal(plan, a), nb = outward_normal(plan, b);
  const double top_a = plan.roof(a) + kBelowFloor, top_b = plan.roof(b) + kBelowFloor;
  const auto vertex = [&](const Eigen::Vector2d& p, const Eigen::Vector2d& n, double z) {
    const double r = plan.roughness(Eigen::Vector3d(p.x(), p.y(), z));
    return Eigen::Vector3f(static_cast<float>(p.x() + n.x() * r), static_cast<float>(p.y() + n.y() * r),
                           static_cast<float>(z));
  };
  const Eigen::Vector2d mid = 0.5 * (a + b);
  for (int k = 0; k < kWallRows; ++k) {
    const double f0 = static_cast<double>(k) / kWallRows, f1 = static_cast<double>(k + 1) / kWallRows;
    const double za0 = -kBelowFloor + f0 * (top_a + kBelowFloor), za1 = -kBelowFloor + f1 * (top_a + kBelowFloor);
    const double zb0 = -kBelowFloor + f0 * (top_b + kBelowFloor), zb1 = -kBelowFloor + f1 * (top_b + kBelowFloor);
    // Rock tone varies from place to place (calibrated reflectivity 10-40 %).
    const auto tone = static_cast<std::uint8_t>(
        std::clamp(plan.wall_reflectivity + 15.0 * value_noise3(plan.seed ^ 0x546F6EULL, mid.x() / 3, mid.y() / 3, za0 / 3),
                   5.0, 100.0));
    mesh.add_quad(vertex(a, na, za0), vertex(b, nb, zb0), vertex(b, nb, zb1), vertex(a, na, za1), tone);
  }
}

}  // namespace

TriangleMesh plan_mesh(const Plan& plan) {
  const double cell_m = plan.cell_m;
  const Grid g = distance_grid(plan, cell_m);
  TriangleMesh mesh;
  const double margin = plan.roughness_m * 2.0 + cell_m;  // floor and roof reach past displaced walls
  const auto floor_vertex = [&](const Eigen::Vector2d& p) {
    return Eigen::Vector3f(static_cast<float>(p.x()), static_cast<float>(p.y()),
                           static_cast<float>(0.2 * plan.roughness(Eigen::Vector3d(p.x(), p.y(), 0.0))));
  };
  const auto roof_vertex = [&](const Eigen::Vector2d& p) {
    const double z = plan.roof(p);
    return Eigen::Vector3f(static_cast<float>(p.x()), static_cast<float>(p.y()),
                           static_cast<float>(z + plan.roughness(Eigen::Vector3d(p.x(), p.y(), z))));
  };
  for (int j = 0; j + 1 < g.ny; ++j) {
    for (int i = 0; i + 1 < g.nx; ++i) {
      const std::array<double, 4> d{g.at(i, j), g.at(i + 1, j), g.at(i + 1, j + 1), g.at(i, j + 1)};
      if (*std::min_element(d.begin(), d.end()) < margin) {
        const Eigen::Vector2d p0 = g.node(i, j), p1 = g.node(i + 1, j), p2 = g.node(i + 1, j + 1), p3 = g.node(i, j + 1);
        mesh.add_quad(floor_vertex(p0), floor_vertex(p1), floor_vertex(p2), floor_vertex(p3), 15);
        mesh.add_quad(roof_vertex(p0), roof_vertex(p3), roof_vertex(p2), roof_vertex(p1), 20);
      }
      int index = 0;
      for (int c = 0; c < 4; ++c) index |= d[c] < 0 ? 1 << c : 0;
      if (index == 0 || index == 15) continue;
      // Crossings on the cell's edges: 0 bottom, 1 right, 2 top, 3 left.
      const auto e = [&](int edge) {
        switch (edge) {
          case 0: return crossing(g, i, j, i + 1, j);
          case 1: return crossing(g, i + 1, j, i + 1, j + 1);
          case 2: return crossing(g, i, j + 1, i + 1, j + 1);
          default: return crossing(g, i, j, i, j + 1);
        }
      };
      const bool centre_inside = (d[0] + d[1] + d[2] + d[3]) < 0;
      switch (index) {
        case 1: case 14: add_wall(plan, e(3), e(0), mesh); break;
        case 2: case 13: add_wall(plan, e(0), e(1), mesh); break;
        case 3: case 12: add_wall(plan, e(3), e(1), mesh); break;
        case 4: case 11: add_wall(plan, e(1), e(2), mesh); break;
        case 6: case 9: add_wall(plan, e(0), e(2), mesh); break;
        case 7: case 8: add_wall(plan, e(3), e(2), mesh); break;
        case 5:  // corners 0 and 2 inside: joined through the centre or not
        case 10:
          if ((index == 5) == centre_inside) {
            add_wall(plan, e(3), e(2), mesh);
            add_wall(plan, e(0), e(1), mesh);
          } else {
            add_wall(plan, e(3), e(0), mesh);
            add_wall(plan, e(1), e(2), mesh);
          }
          break;
        default: break;
      }
    }
  }
  return mesh;
}

}  // namespace adit::sim
