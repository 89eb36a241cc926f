#pragma once
// Whether two maps hold the same points: how many of one have no point of the
// other within a tolerance per axis (a hash of 1 cm cells, each point checked
// against its cell's neighbours; tolerances up to 1 cm).

#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "map_readers.hpp"

namespace adit::test {

// How many of `points` have no point of `reference` within `tolerance_m`
// (a hash of 1 cm cells, each point checked against its cell's neighbours).
inline std::size_t unmatched(const std::vector<XyzI>& points, const std::vector<XyzI>& reference,
                      double tolerance_m) {
  const auto cell = [](double v) { return static_cast<std::int64_t>(std::floor(v / 0.01)); };
  const auto key = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    return (x & 0x1FFFFF) << 42 | (y & 0x1FFFFF) << 21 | (z & 0x1FFFFF);
  };
  std::unordered_multimap<std::int64_t, std::size_t> grid;
  for (std::size_t i = 0; i < reference.size(); ++i)
    grid.emplace(key(cell(reference[i].x), cell(reference[i].y), cell(reference[i].z)), i);
  std::size_t missing = 0;
  for (const XyzI& p : points) {
    bool found = false;
    for (int dx = -1; dx <= 1 && !found; ++dx)
      for (int dy = -1; dy <= 1 && !found; ++dy)
        for (int dz = -1; dz <= 1 && !found; ++dz) {
          const auto [begin, end] = grid.equal_range(key(cell(p.x) + dx, cell(p.y) + dy, cell(p.z) + dz));
          for (auto it = begin; it != end && !found; ++it) {
            const XyzI& q = reference[it->second];
            found = std::abs(p.x - q.x) <= tolerance_m && std::abs(p.y - q.y) <= tolerance_m &&
                    std::abs(p.z - q.z) <= tolerance_m;
          }
        }
    missing += found ? 0 : 1;
  }
  return missing;
}

}  // namespace adit::test
