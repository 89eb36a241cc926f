#include "adit/sim/targets.hpp"

#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::sim {

std::vector<Target> place_targets(const Scene& scene, const RayCaster& caster, int count) {
  std::vector<Target> targets;
  const auto& points = scene.route.points;
  for (int k = 0; k < count; ++k) {
    const auto i = static_cast<std::size_t>((static_cast<double>(k) + 0.5) / count * static_cast<double>(points.size() - 1));
    const Eigen::Vector2d d = points[std::min(i + 1, points.size() - 1)] - points[i > 0 ? i - 1 : 0];
    Eigen::Vector2d side = Eigen::Vector2d(-d.y(), d.x()).normalized();
    if (k % 2 == 1) side = -side;
    const Eigen::Vector3f origin(static_cast<float>(points[i].x()), static_cast<float>(points[i].y()),
                                 static_cast<float>(kTargetHeight));
    const Eigen::Vector3f direction(static_cast<float>(side.x()), static_cast<float>(side.y()), 0.0F);
    const Hit hit = caster.intersect(origin, direction, 0.0F, 50.0F);
    if (!hit.valid()) continue;
    targets.push_back({static_cast<int>(targets.size()) + 1, (origin + hit.distance * direction).cast<double>()});
  }
  return targets;
}

void write_targets_csv(const std::filesystem::path& file, const std::vector<Target>& targets) {
  std::ofstream out(file, std::ios::trunc);
  out << "id,x,y,z\n";
  for (const Target& t : targets) out << fmt::format("{},{:.4f},{:.4f},{:.4f}\n", t.id, t.position.x(), t.position.y(), t.position.z());
  if (!out) throw InputError(file.string(), "", "could not write the targets");
}

}  // namespace adit::sim
