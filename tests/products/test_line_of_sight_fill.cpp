// The 2D line-of-sight fill: free up to an observed obstacle; where a ray
// leaves without meeting one, free only up to the last cell already seen free
// on it; every cell a ray crosses.
#include <gtest/gtest.h>

#include <vector>

#include "adit/products/grid_projection.hpp"

namespace adit::products {
namespace {

// 10 x 10 m at 5 cm, all unknown; a wall along x = 8 m from y = 2 to 8 m.
Grid2d walled() {
  Grid2d g;
  g.resolution_m = 0.05;
  g.width = g.height = 200;
  g.cells.assign(200 * 200, kUnknown);
  for (int r = g.row_of(2.0); r <= g.row_of(8.0); ++r) g.at(g.col_of(8.0), r) = kOccupied;
  return g;
}

TEST(LineOfSightFill, FreeUpToTheWallAndNothingWhereRaysMeetNone) {
  Grid2d g = walled();
  const std::vector<Eigen::Vector3f> view{{2.0F, 5.0F, 0.5F}};
  const std::size_t filled = fill_line_of_sight(g, view, 40.0, 1.0);
  EXPECT_GT(filled, 1000u);
  EXPECT_EQ(g.at(g.col_of(5.0), g.row_of(5.0)), kFree);     // between the viewpoint and the wall
  EXPECT_EQ(g.at(g.col_of(7.85), g.row_of(5.0)), kFree);    // just short of the wall's dilated cells
  EXPECT_EQ(g.at(g.col_of(8.0), g.row_of(5.0)), kOccupied);  // the wall stays
  EXPECT_EQ(g.at(g.col_of(9.0), g.row_of(5.0)), kUnknown);   // behind it
  EXPECT_EQ(g.at(g.col_of(1.0), g.row_of(5.0)), kUnknown);   // away from it: the ray leaves the grid unbounded
  EXPECT_EQ(g.at(g.col_of(5.0), g.row_of(9.5)), kUnknown);   // past the wall's end
}

// A ray through a gap (a door, a sparse far wall) meets no obstacle: it fills
// the unknown cells between free ones it crosses, and nothing past the last.
TEST(LineOfSightFill, AnUnboundedRayFillsOnlyUpToTheLastCellSeenFree) {
  Grid2d g = walled();
  const int row = g.row_of(9.0);  // past the wall's end: the ray along y = 9 m meets nothing
  g.at(g.col_of(4.0), row) = kFree;
  g.at(g.col_of(6.0), row) = kFree;  // the last seen free on it
  const std::vector<Eigen::Vector3f> view{{2.0F, 9.0F, 0.5F}};
  fill_line_of_sight(g, view, 40.0, 1.0);
  EXPECT_EQ(g.at(g.col_of(3.0), row), kFree);
  EXPECT_EQ(g.at(g.col_of(5.0), row), kFree);
  EXPECT_EQ(g.at(g.col_of(7.0), row), kUnknown);
  EXPECT_EQ(g.at(g.col_of(1.0), row), kUnknown);  // the other way nothing was seen
}

TEST(LineOfSightFill, ARayCrossesEveryCellOnItsWay) {
  // A wall on the diagonal from (3, 7) to (7, 3), one cell a step: a ray along
  // the other diagonal must meet it, not slip between two of its cells.
  Grid2d g;
  g.resolution_m = 0.05;
  g.width = g.height = 200;
  g.cells.assign(200 * 200, kUnknown);
  for (int i = 60; i <= 140; ++i) g.at(i, 200 - i) = kOccupied;
  const std::vector<Eigen::Vector3f> view{{2.0F, 2.0F, 0.5F}};
  fill_line_of_sight(g, view, 40.0, 1.0);
  EXPECT_EQ(g.at(g.col_of(4.0), g.row_of(4.0)), kFree);
  EXPECT_EQ(g.at(g.col_of(6.0), g.row_of(6.0)), kUnknown);  // beyond the wall
}

TEST(LineOfSightFill, ViewpointsCloserThanTheStepAreSkipped) {
  Grid2d a = walled(), b = walled();
  const std::vector<Eigen::Vector3f> path{{2.0F, 5.0F, 0.5F}, {2.0F, 3.0F, 0.5F}};
  const std::vector<Eigen::Vector3f> one{{2.0F, 5.0F, 0.5F}};
  fill_line_of_sight(a, path, 40.0, 3.0);  // the second viewpoint is 2 m on: skipped
  fill_line_of_sight(b, one, 40.0, 3.0);
  EXPECT_EQ(a.cells, b.cells);
  EXPECT_GT(fill_line_of_sight(a, path, 40.0, 1.0), 0u);  // taken at a 1 m step: it adds cells
}

}  // namespace
}  // namespace adit::products
