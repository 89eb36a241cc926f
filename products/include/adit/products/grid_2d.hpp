#pragma once
// A 2D occupancy grid as ROS map_server / Nav2 read it (nav_msgs/OccupancyGrid
// values: -1 unknown, 0 free, 100 occupied), row 0 at the lowest y.

#include <cstdint>
#include <vector>

namespace adit::products {

inline constexpr std::int8_t kUnknown = -1;
inline constexpr std::int8_t kFree = 0;
inline constexpr std::int8_t kOccupied = 100;

struct Grid2d {
  double resolution_m = 0.05;
  double origin_x = 0.0, origin_y = 0.0;  // the lower-left corner of cell (0, 0), map frame
  int width = 0, height = 0;
  std::vector<std::int8_t> cells;  // row-major, row 0 at origin_y

  std::int8_t at(int col, int row) const { return cells[static_cast<std::size_t>(row) * width + col]; }
  std::int8_t& at(int col, int row) { return cells[static_cast<std::size_t>(row) * width + col]; }
  bool contains(int col, int row) const { return col >= 0 && row >= 0 && col < width && row < height; }
  // Cell of a map position (may be outside the grid).
  int col_of(double x) const;
  int row_of(double y) const;
  std::size_t count(std::int8_t value) const;
};

}  // namespace adit::products
