#pragma once
// What turns a ray's true hit into a LiDAR return, common to every model:
// range noise, dropouts, the range window and the reflectivity (calibrated
// 0-100 % for diffuse surfaces, 101-255 for retro-reflectors, VLP-16 manual
// §6.3). Every random draw is keyed by (seed, ray index): deterministic and
// independent of threads.

#include <cstdint>
#include <span>

#include <Eigen/Core>

#include "adit/sim/hash_noise.hpp"
#include "adit/sim/mesh.hpp"
#include "adit/sim/ray_caster.hpp"
#include "adit/sim/targets.hpp"

namespace adit::sim {

struct SensorEffects {
  double range_sigma_m = 0.02;
  double dropout = 0.002;  // probability that a return is lost
  double min_range_m = 0.5;
  double max_range_m = 100.0;
};

struct Return {
  bool valid = false;
  double range_m = 0.0;
  std::uint8_t reflectivity = 0;
};

// The random draws of measure(), keyed once per session.
struct SensorNoise {
  explicit SensorNoise(std::uint64_t seed);
  NoiseStream range;
  NoiseStream drop;
};

Return measure(const SensorEffects& effects, const SensorNoise& noise, std::uint64_t ray, const Hit& hit,
               const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, const TriangleMesh& mesh,
               std::span<const Target> targets);

}  // namespace adit::sim
