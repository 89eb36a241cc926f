#pragma once
// Nearest-neighbour-within-a-tolerance queries on a point set, for comparing
// decoded clouds with reference clouds as sets. A hash grid with cells of the
// tolerance's size: a query looks at the 27 cells around it.

#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace adit::test {

class PointGrid {
 public:
  PointGrid(std::vector<std::array<float, 3>> points, float tolerance)
      : points_(std::move(points)), tol_(tolerance) {
    for (std::size_t i = 0; i < points_.size(); ++i) cells_[key(cell(points_[i]))].push_back(i);
  }

  bool has_within(const std::array<float, 3>& p) const {
    const auto c = cell(p);
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(key({c[0] + dx, c[1] + dy, c[2] + dz}));
          if (it == cells_.end()) continue;
          for (const std::size_t i : it->second) {
            const auto& q = points_[i];
            const float ex = q[0] - p[0], ey = q[1] - p[1], ez = q[2] - p[2];
            if (ex * ex + ey * ey + ez * ez <= tol_ * tol_) return true;
          }
        }
      }
    }
    return false;
  }

 private:
  std::array<std::int64_t, 3> cell(const std::array<float, 3>& p) const {
    return {static_cast<std::int64_t>(std::floor(p[0] / tol_)), static_cast<std::int64_t>(std::floor(p[1] / tol_)),
            static_cast<std::int64_t>(std::floor(p[2] / tol_))};
  }
  static std::uint64_t key(const std::array<std::int64_t, 3>& c) {
    return (static_cast<std::uint64_t>(c[0] & 0x1FFFFF) << 42) | (static_cast<std::uint64_t>(c[1] & 0x1FFFFF) << 21) |
           static_cast<std::uint64_t>(c[2] & 0x1FFFFF);
  }

  std::vector<std::array<float, 3>> points_;
  float tol_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
};

}  // namespace adit::test
