#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "adit/eval/mesh_distance.hpp"

namespace adit::eval {
namespace {

using Eigen::Vector3d;

const Triangle kUnit{Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0, 1, 0)};

void expect_closest(const Vector3d& p, const Vector3d& expected, const Triangle& t = kUnit) {
  const Vector3d q = closest_point_on_triangle(p, t);
  EXPECT_NEAR((q - expected).norm(), 0.0, 1e-12) << "p = " << p.transpose() << ", got " << q.transpose();
}

// Each Voronoi region of the unit right triangle in z = 0, worked by hand.
TEST(ClosestPointOnTriangle, FaceRegionProjectsOntoThePlane) {
  expect_closest({0.2, 0.3, 1.0}, {0.2, 0.3, 0.0});
  expect_closest({0.25, 0.25, -2.0}, {0.25, 0.25, 0.0});
}

TEST(ClosestPointOnTriangle, VertexRegions) {
  expect_closest({-1, -1, 0.5}, {0, 0, 0});  // A
  expect_closest({2, -0.5, 0}, {1, 0, 0});   // B: beyond b along ab, below the bc edge normal
  expect_closest({-1, 3, 0}, {0, 1, 0});     // C
}

TEST(ClosestPointOnTriangle, EdgeRegions) {
  expect_closest({0.5, -1, 0.5}, {0.5, 0, 0});   // AB
  expect_closest({-1, 0.5, 0}, {0, 0.5, 0});     // AC
  expect_closest({1, 1, 0}, {0.5, 0.5, 0});      // BC, distance sqrt(0.5)
  expect_closest({0.8, 0.6, 3}, {0.6, 0.4, 0});  // BC off the plane: b + 0.4 (c - b)
}

TEST(ClosestPointOnTriangle, DegenerateTrianglesAreTheirEdges) {
  const Triangle line{Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(2, 0, 0)};
  expect_closest({1.5, 1, 0}, {1.5, 0, 0}, line);
  expect_closest({3, 0, 1}, {2, 0, 0}, line);
  const Triangle dot{Vector3d(1, 2, 3), Vector3d(1, 2, 3), Vector3d(1, 2, 3)};
  expect_closest({0, 0, 0}, {1, 2, 3}, dot);
}

std::vector<Triangle> random_triangles(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> where(0.0, 10.0);
  std::uniform_real_distribution<double> offset(-1.0, 1.0);
  std::vector<Triangle> out;
  for (int i = 0; i < n; ++i) {
    const Vector3d a(where(rng), where(rng), where(rng));
    // Mostly small triangles, some large ones crossing many cells, a few slivers.
    const double size = i % 10 == 0 ? 6.0 : 0.4;
    const Vector3d b = a + size * Vector3d(offset(rng), offset(rng), offset(rng));
    const Vector3d c = i % 17 == 0 ? Vector3d(a + 0.5 * (b - a))
                                   : Vector3d(a + size * Vector3d(offset(rng), offset(rng), offset(rng)));
    out.push_back({a, b, c});
  }
  return out;
}

// A point near the surfaces (up to 2·cap from a random point of a random
// triangle, so about half are within the cap) or, one in eight, anywhere.
Vector3d random_query(std::mt19937& rng, const std::vector<Triangle>& triangles, double cap) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> where(-2.0, 12.0);
  if (rng() % 8 == 0) return {where(rng), where(rng), where(rng)};
  const Triangle& t = triangles[rng() % triangles.size()];
  double u = unit(rng), v = unit(rng);
  if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
  const Vector3d on = t.a + u * (t.b - t.a) + v * (t.c - t.a);
  const Vector3d direction = Vector3d(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5).normalized();
  return on + 2.0 * cap * unit(rng) * direction;
}

// The grid finds exactly what trying every triangle finds, for any cell size,
// including points outside the mesh's box and far away.
TEST(MeshDistance, GridAgreesWithBruteForce) {
  std::mt19937 rng(7);
  const std::vector<Triangle> triangles = random_triangles(rng, 300);
  for (const double cell : {0.0, 0.15, 0.6, 50.0}) {
    for (const double cap : {0.1, 0.8, 2.5}) {
      const MeshDistance mesh(triangles, cap, cell);
      int exact = 0;
      int beyond = 0;
      std::vector<Vector3d> queries;
      for (int i = 0; i < 600; ++i) {
        const Vector3d p = random_query(rng, triangles, cap);
        queries.push_back(p);
        const double truth = brute_force_distance(triangles, p);
        if (std::abs(truth - cap) < 1e-9) continue;  // on the cap: either answer is right
        const double d = mesh.distance(p);
        if (truth < cap) {
          ++exact;
          ASSERT_NEAR(d, truth, 1e-12) << "cell " << mesh.cell() << " cap " << cap << " p " << p.transpose();
        } else {
          ++beyond;
          ASSERT_TRUE(std::isinf(d)) << "cell " << mesh.cell() << " cap " << cap << " got " << d << " truth " << truth;
        }
      }
      // The batch gives each point's own answer, in the input's order.
      const std::vector<double> batch = mesh.distances(queries);
      ASSERT_EQ(batch.size(), queries.size());
      for (std::size_t i = 0; i < queries.size(); ++i) {
        const double one = mesh.distance(queries[i]);
        EXPECT_TRUE(batch[i] == one || (std::isinf(batch[i]) && std::isinf(one))) << i;
      }
      // Both branches were exercised.
      EXPECT_GT(exact, 100) << "cap " << cap;
      EXPECT_GT(beyond, 15) << "cap " << cap;
    }
  }
}

TEST(MeshDistance, PointsOnTheSurfaceAreAtZero) {
  std::mt19937 rng(3);
  const std::vector<Triangle> triangles = random_triangles(rng, 100);
  const MeshDistance mesh(triangles, 1.0);
  for (const Triangle& t : triangles) {
    const Vector3d centroid = (t.a + t.b + t.c) / 3.0;
    EXPECT_NEAR(mesh.distance(centroid), 0.0, 1e-12);
  }
}

TEST(MeshDistance, EmptyMeshAndNonFinitePoints) {
  const MeshDistance empty({}, 1.0);
  EXPECT_TRUE(std::isinf(empty.distance(Vector3d::Zero())));
  const std::vector<Vector3d> two{Vector3d::Zero(), Vector3d::Ones()};
  EXPECT_TRUE(std::isinf(empty.distances(two).at(1)));
  const MeshDistance one({kUnit}, 1.0);
  EXPECT_NEAR(one.distance({0.2, 0.2, 0.5}), 0.5, 1e-15);
  EXPECT_TRUE(std::isnan(one.distance({std::numeric_limits<double>::quiet_NaN(), 0, 0})));
  EXPECT_TRUE(std::isinf(one.distance({100, 0, 0})));
  const std::vector<Vector3d> mixed{{0.2, 0.2, 0.5}, {std::numeric_limits<double>::infinity(), 0, 0}, {0, 0, -0.25}};
  const std::vector<double> d = one.distances(mixed);
  EXPECT_NEAR(d[0], 0.5, 1e-15);
  EXPECT_TRUE(std::isnan(d[1]));
  EXPECT_NEAR(d[2], 0.25, 1e-15);
}

}  // namespace
}  // namespace adit::eval
