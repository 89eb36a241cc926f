#include "adit/products/grid_2d.hpp"

#include <algorithm>
#include <cmath>

namespace adit::products {

int Grid2d::col_of(double x) const { return static_cast<int>(std::floor((x - origin_x) / resolution_m)); }
int Grid2d::row_of(double y) const { return static_cast<int>(std::floor((y - origin_y) / resolution_m)); }
std::size_t Grid2d::count(std::int8_t value) const {
  return static_cast<std::size_t>(std::count(cells.begin(), cells.end(), value));
}

}  // namespace adit::products
