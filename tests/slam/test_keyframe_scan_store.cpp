#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "adit/slam/keyframe_scan_store.hpp"
#include "adit/slam/loop_closer.hpp"

namespace adit::slam {
namespace {

std::vector<Eigen::Vector3f> scan(int k, int n = 500) {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < n; ++i) points.emplace_back(static_cast<float>(k), 0.01F * static_cast<float>(i), -1.5F);
  return points;
}

struct Folder {
  std::filesystem::path path;
  explicit Folder(const std::string& name) : path(std::filesystem::temp_directory_path() / name) {
    std::filesystem::remove_all(path);
  }
  ~Folder() { std::filesystem::remove_all(path); }
};

TEST(KeyframeScanStore, WithoutAFolderEveryScanStaysInRam) {
  KeyframeScanStore store(2);
  for (int k = 0; k < 5; ++k) store.add(scan(k));
  EXPECT_EQ(store.spilled(), 0U);
  EXPECT_GE(store.bytes_in_ram(), 5 * 500 * sizeof(Eigen::Vector3f));
  std::vector<Eigen::Vector3f> out;
  ASSERT_TRUE(store.read(0, out));
  EXPECT_EQ(out, scan(0));
  EXPECT_FALSE(store.read(5, out));
}

TEST(KeyframeScanStore, OlderScansGoToDiskAndComeBackTheSame) {
  const Folder folder("adit_test_kfs_roundtrip");
  KeyframeScanStore store(3);
  store.spill_to(folder.path);
  for (int k = 0; k < 10; ++k) store.add(scan(k, 100 + k));
  EXPECT_EQ(store.spilled(), 7U);  // all but the newest 3
  EXPECT_GE(store.bytes_in_ram(), (107 + 108 + 109) * sizeof(Eigen::Vector3f));  // three scans' worth, not ten
  EXPECT_LE(store.bytes_in_ram(), 3 * 128 * sizeof(Eigen::Vector3f));            // (capacity: 128 each)
  EXPECT_TRUE(std::filesystem::exists(store.file_of(0)));
  EXPECT_FALSE(std::filesystem::exists(store.file_of(9)));
  std::vector<Eigen::Vector3f> out;
  for (int k = 0; k < 10; ++k) {
    ASSERT_TRUE(store.read(static_cast<std::size_t>(k), out)) << store.last_error();
    EXPECT_EQ(out, scan(k, 100 + k)) << k;
  }
  EXPECT_EQ(store.read_errors(), 0U);
}

// A keyframe's descriptor goes to disk with its scan and comes back the same;
// a descriptor read from a damaged file is refused like its scan.
TEST(KeyframeScanStore, DescriptorsGoToDiskWithTheirScans) {
  const Folder folder("adit_test_kfs_descriptor");
  KeyframeScanStore store(2);
  store.spill_to(folder.path);
  const auto bins = [](int k) { return Eigen::MatrixXf::Constant(20, 60, static_cast<float>(k) + 0.5F); };
  for (int k = 0; k < 6; ++k) store.add(scan(k), bins(k));
  EXPECT_EQ(store.spilled(), 4U);
  EXPECT_LE(store.bytes_in_ram(), 2 * (512 * sizeof(Eigen::Vector3f) + 20 * 60 * sizeof(float)));
  Eigen::MatrixXf out;
  std::vector<Eigen::Vector3f> points;
  for (int k = 0; k < 6; ++k) {
    ASSERT_TRUE(store.read_descriptor(static_cast<std::size_t>(k), out)) << store.last_error();
    EXPECT_EQ(out, bins(k)) << k;
    ASSERT_TRUE(store.read(static_cast<std::size_t>(k), points)) << store.last_error();
    EXPECT_EQ(points, scan(k)) << k;
  }
  {  // a flipped byte amid the bins
    std::fstream f(store.file_of(1), std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(40);
    f.put('\x5a');
  }
  EXPECT_FALSE(store.read_descriptor(1, out));
  EXPECT_NE(store.last_error().find(store.file_of(1).string()), std::string::npos);
  EXPECT_NE(store.last_error().find("hash"), std::string::npos);
  EXPECT_EQ(out.size(), 0);
  EXPECT_FALSE(store.read(1, points));
  EXPECT_EQ(store.read_errors(), 2U);
  EXPECT_FALSE(store.read_descriptor(6, out));  // not stored
}

TEST(KeyframeScanStore, ADamagedOrMissingFileIsRefusedNamingIt) {
  const Folder folder("adit_test_kfs_damaged");
  KeyframeScanStore store(1);
  store.spill_to(folder.path);
  for (int k = 0; k < 6; ++k) store.add(scan(k));
  std::vector<Eigen::Vector3f> out;
  {  // a flipped byte amid the points
    std::fstream f(store.file_of(0), std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(100);
    f.put('\x5a');
  }
  EXPECT_FALSE(store.read(0, out));
  EXPECT_NE(store.last_error().find(store.file_of(0).string()), std::string::npos);
  EXPECT_NE(store.last_error().find("hash"), std::string::npos);
  EXPECT_TRUE(out.empty());
  std::filesystem::resize_file(store.file_of(1), 40);  // cut short
  EXPECT_FALSE(store.read(1, out));
  EXPECT_NE(store.last_error().find("short"), std::string::npos);
  { std::ofstream(store.file_of(2), std::ios::binary | std::ios::trunc) << "PLY not this"; }  // another file
  EXPECT_FALSE(store.read(2, out));
  EXPECT_NE(store.last_error().find("tag"), std::string::npos);
  std::filesystem::remove(store.file_of(3));
  EXPECT_FALSE(store.read(3, out));
  EXPECT_EQ(store.read_errors(), 4U);
  ASSERT_TRUE(store.read(4, out));  // the others are unharmed
  EXPECT_EQ(out, scan(4));
}

// A count damaged to claim 2^25 points (400 MB) in a 24-byte file is refused
// by the file's size, before anything is allocated for it.
TEST(KeyframeScanStore, ACountTheFileCannotHoldIsRefusedBeforeItsRamIsTaken) {
  const Folder folder("adit_test_kfs_count");
  KeyframeScanStore store(0);
  store.spill_to(folder.path);
  store.add(scan(0));
  ASSERT_EQ(store.spilled(), 1U);
  const auto write = [&](std::uint64_t n, std::uint32_t rows, std::uint32_t cols) {
    std::ofstream f(store.file_of(0), std::ios::binary | std::ios::trunc);
    const std::uint64_t hash = 0;
    f.write("ADITKFS2", 8);
    f.write(reinterpret_cast<const char*>(&n), sizeof n);
    f.write(reinterpret_cast<const char*>(&rows), sizeof rows);
    f.write(reinterpret_cast<const char*>(&cols), sizeof cols);
    f.write(reinterpret_cast<const char*>(&hash), sizeof hash);
  };
  write(std::uint64_t{1} << 25, 0, 0);
  std::vector<Eigen::Vector3f> out;
  EXPECT_FALSE(store.read(0, out));
  EXPECT_NE(store.last_error().find("short"), std::string::npos) << store.last_error();
  EXPECT_LT(out.capacity(), 1000U);
  write(0, 1U << 12, 1U << 12);  // a descriptor of 2^24 bins (64 MB)
  Eigen::MatrixXf bins;
  EXPECT_FALSE(store.read_descriptor(0, bins));
  EXPECT_NE(store.last_error().find("short"), std::string::npos) << store.last_error();
  EXPECT_EQ(bins.size(), 0);
}

TEST(KeyframeScanStore, AFolderThatCannotBeWrittenKeepsTheScansInRam) {
  const Folder folder("adit_test_kfs_unwritable");
  std::filesystem::create_directories(folder.path);
  { std::ofstream(folder.path / "file") << "x"; }
  KeyframeScanStore store(1);
  store.spill_to(folder.path / "file" / "below");  // under a regular file: cannot be made
  for (int k = 0; k < 4; ++k) store.add(scan(k));
  EXPECT_EQ(store.spilled(), 0U);
  EXPECT_EQ(store.write_errors(), 3U);
  std::vector<Eigen::Vector3f> out;
  ASSERT_TRUE(store.read(0, out));
  EXPECT_EQ(out, scan(0));
}

}  // namespace
}  // namespace adit::slam
