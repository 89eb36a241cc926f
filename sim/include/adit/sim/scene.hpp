#pragma once
// A generated scene: its surfaces, the plan they came from (to check that a
// path stays inside) and the route a platform follows through it.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "adit/sim/mesh.hpp"
#include "adit/sim/plan.hpp"

namespace adit::sim {

struct Route {
  std::vector<Eigen::Vector2d> points;  // evenly spaced by `step`, smooth
  bool closed = false;                  // a loop: the last point leads back to the first (also `step` away)
  double step = kStep;                  // about kStep, so that a loop closes evenly
  double length() const;
  static constexpr double kStep = 0.05;
};

struct Scene {
  std::string name;
  Plan plan;
  TriangleMesh mesh;
  Route route;
  TriangleMesh design;  // the "as designed" model (BIM) where the scene has one, else empty
};

// mine: a loop of drifts (perimeter ~250 m) with bends, a cross-cut (two more
// T-junctions and a second loop), a dead-end branch and a stope off a branch.
Scene make_mine(std::uint64_t seed);
// drift: one straight 200 m drift with smooth walls (no features along its axis).
Scene make_drift(std::uint64_t seed);

// building: an office floor, 3 m high: two corridors joined at both ends (a
// ~100 m loop), rooms on both sides with doors, an open hall with pillars,
// furniture. `design` is the floor as designed: no furniture, and one
// partition 0.3 m from where it was built.
Scene make_building(std::uint64_t seed);

// A polyline split into pieces of at most `max_piece_m`, smoothed by Chaikin
// corner cutting (Chaikin 1974; converges to the quadratic B-spline) and
// resampled every Route::kStep.
Route smooth_route(const std::vector<Eigen::Vector2d>& polyline, bool closed, double max_piece_m = 4.0);

}  // namespace adit::sim
