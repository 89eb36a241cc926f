// PLY, PCD and LAS files read back with readers written independently.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstring>
#include <fstream>
#include <iterator>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/scan_files.hpp"
#include "adit/protocol/map_export.hpp"
#include "adit/protocol/map_import.hpp"
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

// A map in site coordinates (`adit georef`): LAS keeps millimetres at
// E 512 345, N 7 012 345 and carries the CRS as one WKT VLR (LAS 1.4 R15,
// "OGC Coordinate System WKT Record"); PLY keeps them as doubles.
TEST(MapExport, SiteCoordinatesKeepMillimetresAndLasCarriesTheWkt) {
  std::vector<MapPoint> points;
  for (int i = 0; i < 50; ++i)
    points.push_back({512345.6781 + 0.0137 * i, 7012345.4322 - 0.0291 * i, 1234.5 + 0.001 * i, 10.0F, 1.7637e9});
  const std::string wkt = R"(PROJCS["WGS 84 / UTM zone 33N",GEOGCS["WGS 84"],UNIT["metre",1]])";
  const auto las = temp_file("site.las");
  write_map(las, MapFormat::las, points, {.crs_wkt = wkt, .ply_double = false});
  std::ifstream in(las, std::ios::binary);
  const std::string b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto u16 = [&](std::size_t at) { std::uint16_t v; std::memcpy(&v, b.data() + at, 2); return v; };
  const auto u32 = [&](std::size_t at) { std::uint32_t v; std::memcpy(&v, b.data() + at, 4); return v; };
  EXPECT_EQ(u16(6) & (1u << 4), 1u << 4);  // global encoding: WKT
  EXPECT_EQ(u32(96), kLasHeaderSize + kLasVlrHeaderSize + wkt.size() + 1);  // offset to point data
  EXPECT_EQ(u32(100), 1u);                                                   // one VLR
  EXPECT_EQ(b.substr(kLasHeaderSize + 2, 16), std::string("LASF_Projection\0", 16));
  EXPECT_EQ(u16(kLasHeaderSize + 18), 2112u);
  EXPECT_EQ(u16(kLasHeaderSize + 20), wkt.size() + 1);
  EXPECT_EQ(b.substr(kLasHeaderSize + kLasVlrHeaderSize, wkt.size() + 1), wkt + std::string(1, '\0'));
  EXPECT_EQ(b.size(), u32(96) + points.size() * kLasPointFormat6Length);
  const auto back = read_map(las);
  ASSERT_EQ(back.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(back[i].x, points[i].x, 0.0005 + 1e-9);
    EXPECT_NEAR(back[i].y, points[i].y, 0.0005 + 1e-9);
    EXPECT_NEAR(back[i].z, points[i].z, 0.0005 + 1e-9);
  }
  const auto ply = temp_file("site.ply");
  write_map(ply, MapFormat::ply, points, {.crs_wkt = {}, .ply_double = true});
  const auto back_ply = read_map(ply);
  ASSERT_EQ(back_ply.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_DOUBLE_EQ(back_ply[i].x, points[i].x);
    EXPECT_DOUBLE_EQ(back_ply[i].y, points[i].y);
  }
  std::filesystem::remove(las);
  std::filesystem::remove(ply);
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
