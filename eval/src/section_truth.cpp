#include "adit/eval/section_truth.hpp"

#include <cmath>
#include <limits>
#include <vector>

namespace adit::eval {

SectionTruth section_truth(std::span<const Triangle> scene, const Eigen::Vector3d& centre, const Eigen::Vector3d& along_in,
                           double width_at_m) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const Eigen::Vector3d along = Eigen::Vector3d(along_in.x(), along_in.y(), 0.0).normalized();
  const Eigen::Vector3d across(-along.y(), along.x(), 0.0);
  // The cut: segments in (u across, z).
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> cut;
  for (const Triangle& t : scene) {
    const Eigen::Vector3d* v[3] = {&t.a, &t.b, &t.c};
    Eigen::Vector2d ends[2];
    int n = 0;
    for (int i = 0; i < 3 && n < 2; ++i) {
      const Eigen::Vector3d& a = *v[i];
      const Eigen::Vector3d& b = *v[(i + 1) % 3];
      const double da = (a - centre).dot(along), db = (b - centre).dot(along);
      if ((da < 0) == (db < 0) || da == db) continue;
      const Eigen::Vector3d p = a + (b - a) * (da / (da - db));
      ends[n++] = Eigen::Vector2d((p - centre).dot(across), p.z());
    }
    if (n == 2) cut.emplace_back(ends[0], ends[1]);
  }
  SectionTruth s;
  double floor = -kInf, roof = kInf;
  for (const auto& [a, b] : cut) {
    if ((a.x() < 0) == (b.x() < 0) || a.x() == b.x()) continue;
    const double z = a.y() + (b.y() - a.y()) * (-a.x() / (b.x() - a.x()));
    if (z < centre.z()) floor = std::max(floor, z);
    else roof = std::min(roof, z);
  }
  s.floor_z = std::isfinite(floor) ? floor : std::numeric_limits<double>::quiet_NaN();
  s.roof_z = std::isfinite(roof) ? roof : std::numeric_limits<double>::quiet_NaN();
  s.height_m = s.roof_z - s.floor_z;
  const double zw = s.floor_z + width_at_m;
  double left = kInf, right = -kInf;
  for (const auto& [a, b] : cut) {
    if (!std::isfinite(zw) || (a.y() < zw) == (b.y() < zw) || a.y() == b.y()) continue;
    const double u = a.x() + (b.x() - a.x()) * ((zw - a.y()) / (b.y() - a.y()));
    if (u > 0) left = std::min(left, u);
    else right = std::max(right, u);
  }
  s.width_m = std::isfinite(left) && std::isfinite(right) ? left - right : std::numeric_limits<double>::quiet_NaN();
  return s;
}

}  // namespace adit::eval
