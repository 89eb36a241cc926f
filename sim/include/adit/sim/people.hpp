#pragma once
// People walking through the scene: vertical cylinders (0.25 m radius, 1.75 m
// tall) moving along the route, each at its own speed, direction and offset
// from the centre line. They are intersected analytically at each ray's own
// firing time, so a LiDAR sees them move within a scan as it would.

#include <cstdint>
#include <filesystem>
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

// The people's tracks as truth (truth_people.csv), one line per walker every
// `step_s` from 0 to `duration_s`:
//   # comment lines first, then the header
//   t,id,x,y,radius_m,height_m
// t in seconds on the truth files' clock (start_time_ns + seconds since the
// start), x y the cylinder's axis in the world frame (floor at z = 0). Throws
// adit::InputError on I/O failure.
void write_people_truth(const std::filesystem::path& file, const People& people, double duration_s, double step_s,
                        std::int64_t start_time_ns);

// `count` walkers spread along the scene's route (the route must outlive them).
People make_people(const Scene& scene, int count, std::uint64_t seed);

}  // namespace adit::sim
