// PLY, PCD and LAS files read back with readers written independently.
#include <gtest/gtest.h>

#include <unistd.h>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/scan_files.hpp"
#include "adit/protocol/map_export.hpp"
#include "map_readers.hpp"

namespace adit::protocol {
namespace {

std::vector<MapPoint> sample_points() {
  std::vector<MapPoint> points;
  for (int i = 0; i < 500; ++i)
    points.push_back({-12.345 + i * 0.05, 250.5 - i * 0.01, -3.0 + (i % 7) * 0.25, static_cast<float>(i % 256),
                      1'763'700'000.0 + i * 0.1});
  return points;
}

std::filesystem::path temp_file(const std::string& name) {
  return std::filesystem::temp_directory_path() / (std::to_string(::getpid()) + "-" + name);
}

TEST(MapExport, PlyLoadsBack) {
  const auto points = sample_points();
  const auto file = temp_file("map.ply");
  write_map(file, MapFormat::ply, points);
  const auto back = test::read_ply(file);
  ASSERT_EQ(back.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(back[i].x, points[i].x, 1e-4);
    EXPECT_NEAR(back[i].y, points[i].y, 1e-4);
    EXPECT_NEAR(back[i].z, points[i].z, 1e-4);
    EXPECT_EQ(back[i].intensity, points[i].intensity);
  }
  std::filesystem::remove(file);
}

TEST(MapExport, PcdLoadsBack) {
  const auto points = sample_points();
  const auto file = temp_file("map.pcd");
  write_map(file, MapFormat::pcd, points);
  std::vector<drivers::CloudPoint> back;
  drivers::read_pcd(file, back);
  ASSERT_EQ(back.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(back[i].x, points[i].x, 1e-4);
    EXPECT_NEAR(back[i].z, points[i].z, 1e-4);
    EXPECT_EQ(back[i].intensity, points[i].intensity);
  }
  std::filesystem::remove(file);
}

TEST(MapExport, LasHeaderFieldsAndPointsFollowTheSpecification) {
  const auto points = sample_points();
  const auto file = temp_file("map.las");
  write_map(file, MapFormat::las, points);
  const auto back = test::read_las_checked(file);
  ASSERT_EQ(back.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(back[i].x, points[i].x, 0.0005 + 1e-9);
    EXPECT_NEAR(back[i].y, points[i].y, 0.0005 + 1e-9);
    EXPECT_NEAR(back[i].z, points[i].z, 0.0005 + 1e-9);
    EXPECT_EQ(back[i].intensity, points[i].intensity);
    // Adjusted standard GPS time: GPS seconds - 1e9 (LAS 1.4 global encoding bit 0).
    EXPECT_NEAR(back[i].gps_time, points[i].time - 315964800.0 + 18.0 - 1e9, 1e-6);
  }
  std::filesystem::remove(file);
}

TEST(MapExport, EmptyMapsAreValidFiles) {
  const auto file = temp_file("empty.las");
  write_map(file, MapFormat::las, {});
  EXPECT_TRUE(test::read_las_checked(file).empty());
  std::filesystem::remove(file);
}

TEST(MapExport, UnwritablePathsNameTheFile) {
  try {
    write_map("/nonexistent-dir/map.ply", MapFormat::ply, sample_points());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "/nonexistent-dir/map.ply");
  }
}

}  // namespace
}  // namespace adit::protocol
