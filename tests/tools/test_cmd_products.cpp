// End-to-end: `adit products` on a session folder, its files, figures and exit statuses.

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "adit/protocol/map_export.hpp"
#include "adit/slam/tum.hpp"
#include "run_program.hpp"
#include "shared_data.hpp"

namespace adit {
namespace {

using ToolRun = test::CommandRun;
ToolRun adit(const std::string& args) { return test::run_adit(args); }

// A 20 m corridor 3 m wide, the sensor 0.5 m over the floor along its middle.
std::filesystem::path corridor(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("adit_test_cmd_products_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  slam::Trajectory poses;
  for (int k = 0; k <= 40; ++k) {
    slam::Pose p = slam::Pose::Identity();
    p.translation() = Eigen::Vector3d(0.5 * k, 0.0, 0.0);
    poses.push_back(100.0 + 0.5 * k, p);
  }
  slam::write_tum(dir / "map_trajectory.tum", poses);
  std::vector<protocol::MapPoint> points;
  for (double x = -1.99; x <= 22.0; x += 0.05) {
    for (double z = -0.5; z <= 2.5; z += 0.05)
      for (double y : {-1.5, 1.5}) points.push_back({x, y, z, 10.0F, 100.0});
    for (double y = -1.46; y < 1.5; y += 0.05) points.push_back({x, y, -0.5, 10.0F, 100.0});
  }
  protocol::write_map(dir / "map.ply", protocol::MapFormat::ply, points);
  return dir;
}

TEST(AditProducts, WritesEveryProductAndItsFigures) {
  const auto dir = corridor("ok");
  const ToolRun run = adit("products '" + dir.string() + "' --out '" + (dir / "out").string() + "'");
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("storage"), std::string::npos) << run.output;
  for (const char* f : {"occupancy.bt", "grid.pgm", "grid.yaml", "top_view.png", "sections/sections.csv",
                        "sections/section_001.svg", "products.json"})
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / f)) << f;
  std::ifstream in(dir / "out" / "products.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["bytes"]["octree_bt"].get<std::uintmax_t>(), std::filesystem::file_size(dir / "out" / "occupancy.bt"));
  EXPECT_EQ(j["sections"]["count"].get<int>(), 1);  // at 10 m of a 20 m path
}

TEST(AditProducts, BadInputIsNamedWithStatus2) {
  const auto dir = corridor("bad");
  ToolRun run = adit("products '" + dir.string() + "' --grid-resolution 0.005");
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("grid-resolution"), std::string::npos) << run.output;
  std::ofstream(dir / "map_trajectory.tum") << "1.0 0 0 0 0 0 0 1\n2.0 0 0 zero 0 0 0 1\n";
  run = adit("products '" + dir.string() + "'");
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("map_trajectory.tum:2"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "products" / "grid.pgm"));
}

}  // namespace
}  // namespace adit
