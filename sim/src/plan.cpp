#include "adit/sim/plan.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "adit/sim/hash_noise.hpp"

namespace adit::sim {

double Box2::distance(const Eigen::Vector2d& p) const {
  // Signed distance to a box (Quilez's formulation): outside, the distance to the
  // nearest point; inside, minus the distance to the nearest side.
  const Eigen::Vector2d centre = 0.5 * (lo + hi);
  const Eigen::Vector2d half = 0.5 * (hi - lo);
  const Eigen::Vector2d q = (p - centre).cwiseAbs() - half;
  return q.cwiseMax(0.0).norm() + std::min(std::max(q.x(), q.y()), 0.0);
}

double Plan::distance(const Eigen::Vector2d& p) const {
  double d = std::numeric_limits<double>::infinity();
  for (const Drift& s : drifts) {
    const Eigen::Vector2d ab = s.b - s.a;
    const double t = std::clamp((p - s.a).dot(ab) / std::max(ab.squaredNorm(), 1e-12), 0.0, 1.0);
    d = std::min(d, (p - (s.a + t * ab)).norm() - 0.5 * s.width_m);
  }
  for (const Chamber& c : chambers) d = std::min(d, (p - c.centre).norm() - c.radius_m);
  for (const Box2& r : rooms) d = std::min(d, r.distance(p));
  for (const Box2& b : pillars) d = std::max(d, -b.distance(p));
  return d;
}

double Plan::roof(const Eigen::Vector2d& p) const {
  double h = roof_m + roof_variation_m * value_noise3(seed ^ 0x526F6F66ULL, p.x() / 25.0, p.y() / 25.0, 0.5);
  for (const Chamber& c : chambers) {
    const double r = (p - c.centre).norm() / (c.radius_m + 2.0);
    if (r < 1.0) h = std::max(h, roof_m + (c.roof_m - roof_m) * (1.0 - r * r));  // a dome
  }
  return h;
}

double Plan::roughness(const Eigen::Vector3d& p) const {
  // Three octaves: decimetre bumps over ~2 m, then finer, down to centimetres.
  double r = 0.0;
  double amplitude = roughness_m;
  double wavelength = 2.0;
  for (int octave = 0; octave < 3; ++octave) {
    r += amplitude * value_noise3(seed + static_cast<std::uint64_t>(octave), p.x() / wavelength, p.y() / wavelength,
                                  p.z() / wavelength);
    amplitude *= 0.35;
    wavelength *= 0.35;
  }
  return r;
}

}  // namespace adit::sim
