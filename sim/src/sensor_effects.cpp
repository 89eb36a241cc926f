#include "adit/sim/sensor_effects.hpp"

#include <algorithm>
#include <cmath>


namespace adit::sim {
namespace {
constexpr std::uint64_t kRangeStream = 0x52616E6765ULL;
constexpr std::uint64_t kDropStream = 0x44726F70ULL;
}  // namespace

SensorNoise::SensorNoise(std::uint64_t seed) : range(seed, kRangeStream), drop(seed, kDropStream) {}

Return measure(const SensorEffects& e, const SensorNoise& noise, std::uint64_t ray, const Hit& hit,
               const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, const TriangleMesh& mesh,
               std::span<const Target> targets) {
  Return r;
  if (!hit.valid() || noise.drop.uniform(ray) < e.dropout) return r;
  const double range = hit.distance + e.range_sigma_m * noise.range.gaussian(ray);
  if (range < e.min_range_m || range > e.max_range_m) return r;
  r.valid = true;
  r.range_m = range;
  const Eigen::Vector3f point = origin + hit.distance * direction;
  for (const Target& t : targets) {
    if ((point.cast<double>() - t.position).squaredNorm() < kTargetRadius * kTargetRadius) {
      r.reflectivity = 230;  // retro-reflective sheet
      return r;
    }
  }
  // Diffuse (Lambertian) surfaces look darker at grazing incidence.
  const double cos_incidence = std::abs(static_cast<double>(hit.normal.dot(direction)));
  r.reflectivity = static_cast<std::uint8_t>(
      std::clamp(std::lround((hit.dynamic ? hit.reflectivity : mesh.reflectivity[hit.triangle]) * (0.4 + 0.6 * cos_incidence)),
                 1L, 100L));
  return r;
}

}  // namespace adit::sim
