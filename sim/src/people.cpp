#include "adit/sim/people.hpp"

#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "adit/common/error.hpp"

#include "adit/sim/hash_noise.hpp"
#include "adit/sim/route_schedule.hpp"

namespace adit::sim {

Eigen::Vector2d People::position(std::size_t i, double t) const {
  const Walker& w = walkers_[i];
  double s = w.start_m + w.speed_mps * t;
  const double length = route_->length();
  if (!route_->closed) {  // open route: walk to the end and back (a triangle wave)
    s = std::fmod(std::abs(s), 2.0 * length);
    if (s > length) s = 2.0 * length - s;
  }
  const RoutePoint p = route_at(*route_, s);
  return p.position + w.offset_m * Eigen::Vector2d(-std::sin(p.heading), std::cos(p.heading));
}

Hit People::intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float near_m, float far_m,
                      double t) const {
  Hit best;
  const Eigen::Vector2d o(origin.x(), origin.y());
  const Eigen::Vector2d d(direction.x(), direction.y());
  const double a = d.squaredNorm();
  if (a < 1e-12) return best;  // straight up or down: no wall of a cylinder to meet
  for (std::size_t i = 0; i < walkers_.size(); ++i) {
    // |o + s d − c|² = r²  (the cylinder's side, in plan).
    const Eigen::Vector2d m = o - position(i, t);
    const double b = m.dot(d);
    const double c = m.squaredNorm() - kRadius * kRadius;
    const double disc = b * b - a * c;
    if (disc < 0) continue;
    const double s = (-b - std::sqrt(disc)) / a;  // the entry point (outside the person)
    if (s <= near_m || s >= far_m || s >= best.distance) continue;
    const double z = origin.z() + s * direction.z();
    if (z < 0.0 || z > kHeight) continue;
    best.distance = static_cast<float>(s);
    const Eigen::Vector2d n = (m + s * d) / kRadius;
    best.normal = Eigen::Vector3f(static_cast<float>(n.x()), static_cast<float>(n.y()), 0.0F);
    best.dynamic = true;
    best.reflectivity = kReflectivity;
  }
  return best;
}

void write_people_truth(const std::filesystem::path& file, const People& people, double duration_s, double step_s,
                        std::int64_t start_time_ns) {
  std::ofstream out(file, std::ios::trunc);
  out << "# adit sim: the people's tracks (vertical cylinders; floor at z = 0), world frame; t on the truth files' "
         "clock\n";
  out << "t,id,x,y,radius_m,height_m\n";
  const auto steps = static_cast<std::int64_t>(std::floor(duration_s / step_s + 1e-9));
  for (std::int64_t k = 0; k <= steps; ++k) {
    const double t = static_cast<double>(k) * step_s;
    for (std::size_t i = 0; i < people.size(); ++i) {
      const Eigen::Vector2d p = people.position(i, t);
      out << fmt::format("{:.6f},{},{:.4f},{:.4f},{},{}\n", 1e-9 * static_cast<double>(start_time_ns) + t, i, p.x(),
                         p.y(), People::kRadius, People::kHeight);
    }
  }
  out.flush();
  if (!out) throw InputError(file.string(), "", "could not write the people's tracks");
}

People make_people(const Scene& scene, int count, std::uint64_t seed) {
  std::vector<Walker> walkers;
  const double length = scene.route.length();
  for (int k = 0; k < count; ++k) {
    const auto i = static_cast<std::uint64_t>(k);
    Walker w;
    w.start_m = length * (static_cast<double>(k) + uniform(seed, 0x50656F70ULL, 3 * i)) / count;
    w.speed_mps = (0.8 + 0.6 * uniform(seed, 0x50656F70ULL, 3 * i + 1)) * (k % 2 == 0 ? 1.0 : -1.0);
    w.offset_m = 0.4 * (2.0 * uniform(seed, 0x50656F70ULL, 3 * i + 2) - 1.0);
    walkers.push_back(w);
  }
  return People(scene.route, std::move(walkers));
}

}  // namespace adit::sim
