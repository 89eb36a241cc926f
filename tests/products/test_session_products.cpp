#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "adit/common/error.hpp"
#include "adit/products/grid_io.hpp"
#include "adit/products/map_thinning.hpp"
#include "adit/products/session_map.hpp"
#include "adit/products/session_products.hpp"
#include "adit/protocol/map_export.hpp"
#include "adit/protocol/map_import.hpp"
#include "adit/slam/tum.hpp"

namespace adit::products {
namespace {

// A session folder as aditd leaves it, for a straight 3 m wide corridor along
// x (walls at y = ±1.5 m, floor 0.5 m below the sensor): map points (one per
// 5 cm), the map's poses and
// a summary.json.
std::filesystem::path corridor_session(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("adit_test_products_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  slam::Trajectory poses;
  for (int k = 0; k <= 20; ++k) {
    slam::Pose p = slam::Pose::Identity();
    p.translation() = Eigen::Vector3d(0.5 * k, 0.0, 0.0);
    poses.push_back(1000.0 + 0.5 * k, p);
  }
  slam::write_tum(dir / "map_trajectory.tum", poses);
  const auto stamp_of = [&](double x) {
    for (std::size_t k = 0; k < poses.size(); ++k)
      if (std::abs(poses.poses[k].translation().x() - x) < 4.0) return poses.stamps[k];
    return poses.stamps.back();
  };
  std::vector<protocol::MapPoint> points;
  for (double x = -1.99; x <= 12.0; x += 0.05) {  // off the cells' edges, as real points are
    for (double z = -0.5; z <= 2.0; z += 0.05)
      for (double y : {-1.5, 1.5}) points.push_back({x, y, z, 10.0F, stamp_of(x)});
    for (double y = -1.46; y < 1.5; y += 0.05) points.push_back({x, y, -0.5, 10.0F, stamp_of(x)});
  }
  protocol::write_map(dir / "map.ply", protocol::MapFormat::ply, points);
  std::ofstream(dir / "summary.json") << R"({"id": "test", "map": {"points": 1}})";
  return dir;
}

TEST(SessionProducts, CorridorGridHasWallsFreeFloorAndUnknownBeyond) {
  const auto dir = corridor_session("corridor");
  ProductsOptions options;
  const ProductsReport r = write_session_products(dir, options);
  EXPECT_EQ(r.out_dir, dir / "products");
  for (const char* f : {"occupancy.bt", "grid.pgm", "grid.yaml", "products.json"})
    EXPECT_TRUE(std::filesystem::exists(dir / "products" / f)) << f;
  EXPECT_GT(r.ground_points, 0u);
  const Grid2d g = read_grid(dir / "products" / "grid.yaml");
  const auto at = [&](double x, double y) { return g.at(g.col_of(x), g.row_of(y)); };
  EXPECT_EQ(at(5.0, 1.5), kOccupied);
  EXPECT_EQ(at(5.0, -1.5), kOccupied);
  EXPECT_EQ(at(5.0, 0.0), kFree);
  EXPECT_EQ(at(5.0, 1.0), kFree);
  // Along the corridor between the walls, nearly every cell is free.
  std::size_t free = 0, cells = 0;
  for (double x = 1.0; x < 9.0; x += 0.05)
    for (double y = -1.35; y < 1.35; y += 0.05, ++cells) free += at(x, y) == kFree;
  EXPECT_GT(free, 0.95 * cells);
  // The figures went to summary.json, the rest of it kept.
  std::ifstream in(dir / "summary.json");
  const nlohmann::json s = nlohmann::json::parse(in);
  EXPECT_EQ(s["id"], "test");
  EXPECT_EQ(s["products"]["bytes"]["octree_bt"], r.bt_bytes);
  EXPECT_EQ(s["products"]["bytes"]["grid"], r.grid_bytes);
  EXPECT_EQ(r.bt_bytes, std::filesystem::file_size(dir / "products" / "occupancy.bt"));
  // Each step's CPU time, in order, adding up to the whole (less what runs after the last lap).
  const nlohmann::json& steps = s["products"]["cpu_by_step_s"];
  ASSERT_EQ(steps.size(), r.cpu_by_step.size());
  double sum = 0.0;
  for (const auto& [step, seconds] : r.cpu_by_step) {
    EXPECT_GE(seconds, 0.0) << step;
    EXPECT_EQ(steps[step], seconds) << step;
    sum += seconds;
  }
  for (const char* step : {"read_map", "moving_objects", "rays_to_path", "octree", "grid", "top_view", "sections"})
    EXPECT_TRUE(steps.contains(step)) << step;
  EXPECT_LE(sum, r.cpu_s + 1e-9);
  EXPECT_GE(sum, 0.5 * r.cpu_s);
}

TEST(SessionProducts, FinerGridAndOtherFolder) {
  const auto dir = corridor_session("fine");
  ProductsOptions options;
  options.grid_resolution_m = 0.01;
  options.write_ot = true;
  const ProductsReport r = write_session_products(dir, options, dir / "out");
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "occupancy.ot"));
  const Grid2d g = read_grid(dir / "out" / "grid.yaml");
  EXPECT_DOUBLE_EQ(g.resolution_m, 0.01);
  EXPECT_EQ(g.at(g.col_of(5.0), g.row_of(0.0)), kFree);
  EXPECT_GT(r.ot_bytes, 0u);
}

TEST(SessionProducts, APlaceMappedOnTwoLapsIsThinnedToOnePointPerMapVoxel) {
  // The corridor as one lap, and as two: the second lap's points 1 cm from
  // the first's, in the same 5 cm voxels (the loop closure moved them there).
  const auto once = corridor_session("one_lap");
  const auto twice = corridor_session("two_laps");
  std::vector<protocol::MapPoint> points = protocol::read_map(twice / "map.ply");
  const std::size_t lap = points.size();
  for (std::size_t i = 0; i < lap; ++i) {
    protocol::MapPoint p = points[i];
    p.x += 0.01;
    points.push_back(p);
  }
  protocol::write_map(twice / "map.ply", protocol::MapFormat::ply, points);
  // Thinned to the session's own map voxel (config.yaml) by default.
  std::ofstream(twice / "config.yaml") << "payload:\n  id: test\nlidar:\n  model: VLP-16\nmap:\n  voxel_m: 0.05\n";
  const ProductsReport r = write_session_products(twice, ProductsOptions{});
  EXPECT_EQ(r.read_points, 2 * lap);
  EXPECT_DOUBLE_EQ(r.thin_voxel_m, 0.05);
  // Thinned as the file is read: the points thin_to_voxels keeps of the whole file, in order.
  {
    std::vector<protocol::MapPoint> whole = protocol::read_map(twice / "map.ply");
    const std::size_t dropped = thin_to_voxels(whole, 0.05);
    const SessionInputs in = read_session_inputs(twice, -1.0);
    EXPECT_EQ(in.read_points, 2 * lap);
    EXPECT_EQ(in.thinned, dropped);
    ASSERT_EQ(in.points.size(), whole.size());
    for (std::size_t i = 0; i < whole.size(); ++i) {
      ASSERT_EQ(in.points[i].x, whole[i].x) << i;
      ASSERT_EQ(in.points[i].y, whole[i].y) << i;
      ASSERT_EQ(in.points[i].z, whole[i].z) << i;
    }
    EXPECT_EQ(read_session_inputs(twice).points.size(), 2 * lap) << "0, the default: every point";
  }
  // The one lap alone, thinned the same (its own few duplicates: samples 5 cm
  // apart whose rounding put two in one voxel).
  ProductsOptions same_voxel;
  same_voxel.thin_voxel_m = 0.05;
  const ProductsReport one = write_session_products(once, same_voxel);
  // The second lap adds nothing: the first lap's points are the ones kept, and the products are the one lap's.
  EXPECT_EQ(r.thinned, lap + one.thinned);
  EXPECT_EQ(r.points, one.points);
  const Grid2d a = read_grid(once / "products" / "grid.yaml");
  const Grid2d b = read_grid(twice / "products" / "grid.yaml");
  EXPECT_EQ(a.cells, b.cells);
  std::ifstream in(twice / "products" / "products.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["read_points"], 2 * lap);
  EXPECT_EQ(j["thinning"]["dropped"], r.thinned);
  // 0 keeps every point; without a config.yaml nothing is thinned either.
  ProductsOptions keep_all;
  keep_all.thin_voxel_m = 0.0;
  EXPECT_EQ(write_session_products(twice, keep_all).thinned, 0U);
  std::filesystem::remove(twice / "config.yaml");
  EXPECT_EQ(write_session_products(twice, ProductsOptions{}).thinned, 0U);
}

TEST(SessionProducts, BadOptionsAndMissingFilesAreInputErrors) {
  const auto dir = corridor_session("bad");
  ProductsOptions options;
  options.grid_resolution_m = 0.005;
  EXPECT_THROW(write_session_products(dir, options), InputError);
  options = ProductsOptions{};
  options.thin_voxel_m = 2.0;
  EXPECT_THROW(write_session_products(dir, options), InputError);
  std::filesystem::remove(dir / "map_trajectory.tum");
  try {
    write_session_products(dir, ProductsOptions{});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(e.where().find("map_trajectory.tum"), std::string::npos);
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "products" / "grid.pgm"));  // nothing written
}

}  // namespace
}  // namespace adit::products
