#pragma once
// Exact point-to-mesh distance: how far a map point lies from the nearest
// triangle of a reference surface (the simulator's scene, a BIM model).
// Triangles are bucketed in a uniform grid; a query visits cells in growing
// shells around the point and stops as soon as no unvisited cell can hold a
// closer triangle, or when everything left is beyond the cap.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Geometry>  // cross products

namespace adit::eval {

struct Triangle {
  Eigen::Vector3d a, b, c;
};

// The point of triangle abc nearest to p: Ericson, "Real-Time Collision
// Detection" (2005), §5.1.5, by the Voronoi region of p (vertex, edge or
// face). A degenerate (zero-area) triangle is treated as its three edges.
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Triangle& t);

// Distance from p to the nearest triangle by trying them all (tests, baselines).
double brute_force_distance(std::span<const Triangle> triangles, const Eigen::Vector3d& p);

class MeshDistance {
 public:
  // `cap` (m, > 0): distances above it are not computed exactly. `cell` (m):
  // grid spacing; 0 picks one from the mesh's extent and triangle count.
  MeshDistance(std::vector<Triangle> triangles, double cap, double cell = 0.0);

  // Exact distance to the nearest triangle when it is below cap; +infinity
  // when every triangle is at least cap away (or there are none); NaN for a
  // non-finite p. `cap` must stay small beside the grid (the caller bounds it).
  double distance(const Eigen::Vector3d& p) const;

  // distance() of every point, visited in grid-cell order so that queries
  // next to each other in space run one after another (2x faster on a map
  // in random order: the cells' triangles stay in cache).
  std::vector<double> distances(std::span<const Eigen::Vector3d> points) const;

  double cap() const { return cap_; }
  double cell() const { return cell_; }
  std::size_t size() const { return triangles_.size(); }

 private:
  struct Box {
    Eigen::Vector3d lo, hi;
  };
  template <typename Visit>
  void for_cells_overlapping(const Triangle& t, Visit&& visit) const;
  double squared_distance_in_cell(std::int64_t cell, const Eigen::Vector3d& p, double best_sq) const;

  std::vector<Triangle> triangles_;
  std::vector<Box> boxes_;  // per triangle, for a cheap lower bound
  double cap_;
  double cell_ = 1.0;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();  // corner of cell (0, 0, 0)
  Eigen::Array3i dims_ = Eigen::Array3i::Zero();
  Box bounds_;                                 // of all triangles
  std::vector<std::uint32_t> cell_start_;      // CSR: triangles of cell k are
  std::vector<std::uint32_t> cell_triangles_;  // cell_triangles_[start[k], start[k+1])
};

}  // namespace adit::eval
