#pragma once
// People walking through the scene: vertical cylinders (0.25 m radius, 1.75 m
// tall) moving along the route, each at its own speed, direction and offset
// from the centre line. They are intersected analytically at each ray's own
// firing time, so a LiDAR sees them move within a scan as it would.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "adit/sim/ray_caster.hpp"
#include "adit/sim/scene.hpp"

namespace adit::sim {

struct Walker {
  double start_m = 0.0;   // arc length along the route at t = 0
  double speed_mps = 1.2;  // signed: against the route's direction when negative
  double offset_m = 0.0;  // to the left of the centre line
};

class People {
 public:
  static constexpr double kRadius = 0.25;
  static constexpr double kHeight = 1.75;
  static constexpr std::uint8_t kReflectivity = 35;  // clothing

  People() = default;
  People(const Route& route, std::vector<Walker> walkers) : route_(&route), walkers_(std::move(walkers)) {}

  bool empty() const { return walkers_.empty(); }
  std::size_t size() const { return walkers_.size(); }
  // Where walker i stands at time t (seconds since the start), floor level.
  Eigen::Vector2d position(std::size_t i, double t) const;
  // The nearest person along the ray within (near, far) at time t, as a Hit
  // (dynamic, with the people's reflectivity); invalid when none.
  Hit intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float near_m, float far_m,
                double t) const;

 private:
  const Route* route_ = nullptr;
  std::vector<Walker> walkers_;
};

// `count` walkers spread along the scene's route (the route must outlive them).
People make_people(const Scene& scene, int count, std::uint64_t seed);

}  // namespace adit::sim
