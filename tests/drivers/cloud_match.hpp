#pragma once
// Test support: matching two point sets within a distance, through a hash
// grid of cells the size of the tolerance (27 neighbouring cells searched).

#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace adit::test {

struct Xyz {
  float x, y, z;
};

class PointGrid {
 public:
  PointGrid(const std::vector<Xyz>& points, float cell) : points_(points), cell_(cell) {
    for (std::size_t i = 0; i < points.size(); ++i) cells_[key(cell_of(points[i].x), cell_of(points[i].y), cell_of(points[i].z))].push_back(i);
  }
  bool has_within(const Xyz& p, float tolerance) const {
    const float t2 = tolerance * tolerance;
    const std::int64_t cx = cell_of(p.x), cy = cell_of(p.y), cz = cell_of(p.z);
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(key(cx + dx, cy + dy, cz + dz));
          if (it == cells_.end()) continue;
          for (const std::size_t i : it->second) {
            const Xyz& q = points_[i];
            const float ex = q.x - p.x, ey = q.y - p.y, ez = q.z - p.z;
            if (ex * ex + ey * ey + ez * ez <= t2) return true;
          }
        }
    return false;
  }

 private:
  std::int64_t cell_of(float v) const { return static_cast<std::int64_t>(std::floor(v / cell_)); }
  static std::int64_t key(std::int64_t x, std::int64_t y, std::int64_t z) {
    return (x & 0x1FFFFF) | (y & 0x1FFFFF) << 21 | (z & 0x1FFFFF) << 42;
  }
  const std::vector<Xyz>& points_;
  float cell_;
  std::unordered_map<std::int64_t, std::vector<std::size_t>> cells_;
};

}  // namespace adit::test
