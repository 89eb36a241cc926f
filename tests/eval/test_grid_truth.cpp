#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "adit/eval/grid_truth.hpp"

namespace adit::eval {
namespace {

// A closed 4 x 3 m room (walls from z = -0.5 to 3 m), its walls centred in
// cells of the 5 cm lattice that starts at (-1, -1).
std::vector<Triangle> room() {
  const double x0 = 0.025, x1 = 4.025, y0 = 0.025, y1 = 3.025, z0 = -0.5, z1 = 3.0;
  std::vector<Triangle> t;
  const auto quad = [&](Eigen::Vector3d a, Eigen::Vector3d b) {  // a vertical wall from a to b (floor points)
    const Eigen::Vector3d up(0, 0, z1 - z0);
    t.push_back({a, b, b + up});
    t.push_back({a, b + up, a + up});
  };
  quad({x0, y0, z0}, {x1, y0, z0});
  quad({x1, y0, z0}, {x1, y1, z0});
  quad({x1, y1, z0}, {x0, y1, z0});
  quad({x0, y1, z0}, {x0, y0, z0});
  return t;
}

struct TestGrid {
  std::vector<std::int8_t> cells;
  GridView view() const { return {0.05, -1.0, -1.0, 140, 120, cells}; }
};

// The room as a mapper would see it from inside, walls shifted by `shift` cells in x.
TestGrid room_grid(int shift) {
  TestGrid g;
  g.cells.assign(140 * 120, -1);
  const auto cell = [](double v) { return static_cast<int>(std::floor((v + 1.0) / 0.05)); };
  for (int r = cell(0.025); r <= cell(3.025); ++r)
    for (int c = cell(0.025); c <= cell(4.025); ++c) {
      const bool wall = r == cell(0.025) || r == cell(3.025) || c == cell(0.025) || c == cell(4.025);
      g.cells[static_cast<std::size_t>(r) * 140 + c + (wall ? shift : 0)] = wall ? 100 : 0;
    }
  return g;
}

TEST(GridTruth, APerfectGridScoresOne) {
  const std::vector<Eigen::Vector3d> path = {{2.0, 1.5, 0.5}, {2.5, 1.5, 0.5}};
  const TestGrid g = room_grid(0);
  const GridTruthScore s = score_grid(g.view(), room(), Eigen::Isometry3d::Identity(), path, GridTruthOptions{});
  EXPECT_GT(s.iou_free, 0.99);
  EXPECT_GT(s.iou_occupied, 0.98);
  EXPECT_GT(s.iou_occupied_within_1_cell, 0.98);
  EXPECT_GT(s.truth_occupied, 2 * (80 + 60) - 10u);
}

TEST(GridTruth, ShiftedWallsAndUnknownCellsScoreLow) {
  const std::vector<Eigen::Vector3d> path = {{2.0, 1.5, 0.5}};
  const TestGrid shifted = room_grid(2);
  const GridTruthScore s = score_grid(shifted.view(), room(), Eigen::Isometry3d::Identity(), path, GridTruthOptions{});
  EXPECT_LT(s.iou_occupied, 0.6);  // the two long walls still overlap, the short ones are 10 cm off
  EXPECT_LT(s.iou_occupied_within_1_cell, 0.75);
  TestGrid unknown;
  unknown.cells.assign(140 * 120, -1);
  const GridTruthScore u = score_grid(unknown.view(), room(), Eigen::Isometry3d::Identity(), path, GridTruthOptions{});
  EXPECT_EQ(u.iou_free, 0.0);
  EXPECT_EQ(u.iou_known, 0.0);
}

TEST(GridTruth, EachCellSaysWhereTheGridAndTheTruthAgree) {
  const std::vector<Eigen::Vector3d> path = {{2.0, 1.5, 0.5}};
  TestGrid g = room_grid(0);
  const auto at = [](double x, double y) { return static_cast<std::size_t>(std::floor((y + 1.0) / 0.05)) * 140 +
                                                  static_cast<std::size_t>(std::floor((x + 1.0) / 0.05)); };
  g.cells[at(1.0, 1.0)] = -1;   // a free cell the grid does not know
  g.cells[at(3.0, 2.0)] = 100;  // an obstacle the room does not have
  g.cells[at(5.5, 1.0)] = 0;    // free outside the room, where no ray from the path goes
  const GridTruthScore s = score_grid(g.view(), room(), Eigen::Isometry3d::Identity(), path, GridTruthOptions{});
  ASSERT_EQ(s.cells.size(), static_cast<std::size_t>(s.lattice_width) * s.lattice_height);
  EXPECT_EQ(s.lattice_width, 140);
  EXPECT_EQ(s.cells[at(2.0, 2.0)], CellAgreement::free_both);
  EXPECT_EQ(s.cells[at(1.0, 1.0)], CellAgreement::free_truth_unknown);
  EXPECT_EQ(s.cells[at(3.0, 2.0)], CellAgreement::occupied_grid_only);
  EXPECT_EQ(s.cells[at(0.025, 1.5)], CellAgreement::occupied_both);
  EXPECT_EQ(s.cells[at(5.5, 1.0)], CellAgreement::free_grid_only);
  EXPECT_EQ(s.cells[at(5.5, 2.0)], CellAgreement::unseen_both);
  std::size_t both = 0;
  for (const CellAgreement a : s.cells) both += a == CellAgreement::free_both;
  EXPECT_EQ(static_cast<double>(both) / static_cast<double>(s.truth_free + s.grid_free - both), s.iou_free);
}

TEST(GridTruth, TheSceneIsPlacedInTheGridsFrame) {
  // A height offset between the frames changes nothing; a 0.5 m shift is seen.
  Eigen::Isometry3d map_from_world = Eigen::Isometry3d::Identity();
  map_from_world.translation() = Eigen::Vector3d(0.0, 0.0, 0.3);  // height does not matter
  const std::vector<Eigen::Vector3d> path = {{2.0, 1.5, 0.5}};
  const TestGrid g = room_grid(0);
  const GridTruthScore s = score_grid(g.view(), room(), map_from_world, path, GridTruthOptions{});
  EXPECT_GT(s.iou_free, 0.99);
  map_from_world.translation() = Eigen::Vector3d(0.5, 0.0, 0.0);
  EXPECT_LT(score_grid(g.view(), room(), map_from_world, path, GridTruthOptions{}).iou_free, 0.9);
}

}  // namespace
}  // namespace adit::eval
