#include "adit/sim/sensor_effects.hpp"

#include <algorithm>
#include <cmath>

#include "adit/sim/hash_noise.hpp"

namespace adit::sim {
namespace {
constexpr std::uint64_t kRangeStream = 0x52616E6765ULL;
constexpr std::uint64_t kDropStream = 0x44726F70ULL;
}  // namespace

Return measure(const SensorEffects& e, std::uint64_t seed, std::uint64_t ray, const Hit& hit,
               const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, const TriangleMesh& mesh,
               std::span<const Target> targets) {
  Return r;
  if (!hit.valid() || uniform(seed, kDropStream, ray) < e.dropout) return r;
  const double range = hit.distance + e.range_sigma_m * gaussian(seed, kRangeStream, ray);
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
