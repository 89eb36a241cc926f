#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "adit/common/error.hpp"
#include "adit/drivers/lidar/scan_directory.hpp"
#include "adit/drivers/lidar/scan_files.hpp"
#include "pcap_builder.hpp"

namespace adit::drivers {
namespace {

std::filesystem::path fresh_dir(const std::string& name) {
  const auto dir = test::scratch_file(name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

TEST(ScanFiles, PcdWrittenByUsReadsBack) {
  LidarScan scan;
  for (int i = 0; i < 5; ++i) {
    LidarPoint p;
    p.x = static_cast<float>(i);
    p.y = -1.5F * static_cast<float>(i);
    p.z = 0.25F;
    p.intensity = 10.0F + static_cast<float>(i);
    p.ring = static_cast<std::uint16_t>(i);
    scan.points.push_back(p);
  }
  const auto dir = fresh_dir("pcd-roundtrip");
  write_pcd(dir / "a.pcd", scan);
  std::vector<CloudPoint> cloud;
  read_pcd(dir / "a.pcd", cloud);
  ASSERT_EQ(cloud.size(), 5u);
  EXPECT_FLOAT_EQ(cloud[3].x, 3.0F);
  EXPECT_FLOAT_EQ(cloud[3].y, -4.5F);
  EXPECT_FLOAT_EQ(cloud[3].intensity, 13.0F);
  write_ply(dir / "a.ply", scan);
  EXPECT_GT(std::filesystem::file_size(dir / "a.ply"), 5u * 27u);
  std::filesystem::remove_all(dir);
}

TEST(ScanDirectorySource, ReadsAsciiPcdAndKittiInNameOrder) {
  const auto dir = fresh_dir("scan-dir");
  write_text(dir / "000001.pcd",
             "# ascii\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 2\n"
             "HEIGHT 1\nPOINTS 2\nDATA ascii\n1 2 2 7\nnan nan nan 0\n");
  const float kitti[] = {3.0F, 4.0F, 0.0F, 0.5F};
  std::ofstream(dir / "000000.bin", std::ios::binary).write(reinterpret_cast<const char*>(kitti), sizeof kitti);
  write_text(dir / "notes.txt", "ignored");
  ScanDirectorySource source(dir, 100'000'000);
  ASSERT_EQ(source.size(), 2u);
  LidarScan scan;
  ASSERT_TRUE(source.next(scan));  // 000000.bin first
  ASSERT_EQ(scan.points.size(), 1u);
  EXPECT_FLOAT_EQ(scan.points[0].range_m, 5.0F);
  EXPECT_FLOAT_EQ(scan.points[0].intensity, 0.5F);
  ASSERT_TRUE(source.next(scan));
  ASSERT_EQ(scan.points.size(), 1u);  // the NaN point is "no return"
  EXPECT_FLOAT_EQ(scan.points[0].range_m, 3.0F);
  EXPECT_EQ(scan.sensor_start_time_ns, 100'000'000);
  EXPECT_FALSE(source.next(scan));
  std::filesystem::remove_all(dir);
}

TEST(ScanDirectorySource, DamagedFilesNameThemselves) {
  const auto dir = fresh_dir("scan-dir-bad");
  write_text(dir / "a.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nPOINTS 100\nDATA binary\nxx");
  write_text(dir / "b.bin", "123");
  write_text(dir / "c.pcd", "VERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\nPOINTS 0\nDATA ascii\n");
  write_text(dir / "d.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nPOINTS 1\nDATA binary_compressed\n");
  ScanDirectorySource source(dir);
  LidarScan scan;
  for (const char* name : {"a.pcd", "b.bin", "c.pcd", "d.pcd"}) {
    try {
      source.next(scan);
      FAIL() << name << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(e.where().find(name), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove_all(dir);
  EXPECT_THROW(ScanDirectorySource{dir}, InputError);
}

}  // namespace
}  // namespace adit::drivers
