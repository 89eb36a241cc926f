// Map files written by write_map read back by read_map, and bad files named.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <span>
#include <string>

#include "adit/common/error.hpp"
#include "adit/protocol/map_export.hpp"
#include "adit/protocol/map_import.hpp"
#include "map_readers.hpp"

namespace adit::protocol {
namespace {

std::vector<MapPoint> sample_points() {
  std::vector<MapPoint> points;
  for (int i = 0; i < 300; ++i)
    points.push_back({-12.345 + i * 0.05, 250.5 - i * 0.01, -3.0 + (i % 7) * 0.25, static_cast<float>(i % 256),
                      1'763'700'000.0 + i * 0.1});
  return points;
}

class MapImport : public ::testing::Test {
 protected:
  std::filesystem::path file(const std::string& name) {
    auto f = std::filesystem::temp_directory_path() / (std::to_string(::getpid()) + "-import-" + name);
    files_.push_back(f);
    return f;
  }
  ~MapImport() override {
    for (const auto& f : files_) std::filesystem::remove(f);
  }
  // The InputError's `where` when reading `f`, or "" when it reads fine.
  static std::string error_of(const std::filesystem::path& f) {
    try {
      read_map(f);
    } catch (const InputError& e) {
      EXPECT_NE(e.reason(), "");
      return e.where();
    }
    return "";
  }

 private:
  std::vector<std::filesystem::path> files_;
};

void expect_same(const std::vector<MapPoint>& back, const std::vector<MapPoint>& points, double tolerance) {
  ASSERT_EQ(back.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(back[i].x, points[i].x, tolerance) << i;
    EXPECT_NEAR(back[i].y, points[i].y, tolerance) << i;
    EXPECT_NEAR(back[i].z, points[i].z, tolerance) << i;
    EXPECT_EQ(back[i].intensity, points[i].intensity) << i;
  }
}

TEST_F(MapImport, EveryFormatReadsBackWhatWriteMapWrote) {
  const auto points = sample_points();
  // PLY and PCD hold float32 (~3e-5 m at 250 m), LAS 1 mm integers.
  for (const auto& [name, format, tolerance] : {std::tuple{"map.ply", MapFormat::ply, 1e-4},
                                                {"map.pcd", MapFormat::pcd, 1e-4},
                                                {"map.LAS", MapFormat::las, 5e-4}}) {
    const auto f = file(name);
    write_map(f, format, points);
    SCOPED_TRACE(name);
    expect_same(read_map(f), points, tolerance);
  }
  const auto las = read_map(file("map.LAS"));
  EXPECT_NEAR(las.back().time, points.back().time, 1e-6) << "Adjusted Standard GPS Time back to Unix seconds";
}

TEST_F(MapImport, EmptyMapsReadAsEmpty) {
  for (const auto& [name, format] :
       {std::pair{"empty.ply", MapFormat::ply}, {"empty.pcd", MapFormat::pcd}, {"empty.las", MapFormat::las}}) {
    const auto f = file(name);
    write_map(f, format, {});
    EXPECT_TRUE(read_map(f).empty()) << name;
  }
}

TEST_F(MapImport, TruncatedFilesAreNamed) {
  for (const char* name : {"cut.ply", "cut.pcd", "cut.las"}) {
    const auto f = file(name);
    write_map(f, map_format_of(f), sample_points());
    std::filesystem::resize_file(f, std::filesystem::file_size(f) - 7);
    EXPECT_EQ(error_of(f), f.string()) << name;
  }
  const auto f = file("header.las");
  write_map(f, MapFormat::las, sample_points());
  std::filesystem::resize_file(f, 100);
  EXPECT_EQ(error_of(f), f.string());
}

TEST_F(MapImport, BadFilesAreNamed) {
  const auto write = [&](const std::string& name, const std::string& bytes) {
    const auto f = file(name);
    std::ofstream(f, std::ios::binary) << bytes;
    return f;
  };
  EXPECT_EQ(error_of(write("map.xyz", "1 2 3\n")), file("map.xyz").string());
  EXPECT_EQ(error_of(write("text.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n")),
            file("text.ply").string() + ":2");
  EXPECT_EQ(error_of(write("noz.ply",
                           "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n"
                           "property float y\nend_header\n")),
            file("noz.ply").string());
  EXPECT_EQ(error_of(write("faces.ply",
                           "ply\nformat binary_little_endian 1.0\nelement face 0\n"
                           "property list uchar uint vertex_indices\nend_header\n")),
            file("faces.ply").string());
  EXPECT_EQ(error_of(write("ascii.pcd",
                           "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\n"
                           "HEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n")),
            file("ascii.pcd").string() + ":9");
  EXPECT_EQ(error_of(write("fields.pcd", "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nPOINTS 0\nDATA binary\n")),
            file("fields.pcd").string());
  EXPECT_EQ(error_of(write("nolas.las", std::string(400, 'x'))), file("nolas.las").string());
  EXPECT_EQ(error_of(file("missing.ply")), file("missing.ply").string());
}

TEST_F(MapImport, NonFiniteCoordinatesAreRefused) {
  const auto f = file("nan.ply");
  const std::vector<MapPoint> points{MapPoint{0, 0, 0, 0, 0}, MapPoint{std::nan(""), 0, 0, 0, 0}};
  write_map(f, MapFormat::ply, points);
  try {
    read_map(f);
    FAIL() << "read a NaN coordinate";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), f.string());
    EXPECT_EQ(e.key(), "point 1");
  }
}

// A file read a block at a time (MapFileReader) gives the points read_map
// gives from the file's bytes, in order, across block boundaries (64 Ki).
TEST_F(MapImport, AFileReadInBlocksGivesThePointsOfTheWholeFile) {
  std::vector<MapPoint> points;
  for (int i = 0; i < 150'000; ++i)
    points.push_back({0.001 * i, -0.002 * i, 0.5 * (i % 11), static_cast<float>(i % 60'000), 1'763'700'000.0 + i});
  for (const char* name : {"blocks.ply", "blocks.pcd", "blocks.las"}) {
    SCOPED_TRACE(name);
    const auto f = file(name);
    write_map(f, map_format_of(f), points);
    std::ifstream in(f, std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    const std::vector<MapPoint> whole = read_map(bytes, map_format_of(f), f.string());
    MapFileReader reader(f);
    EXPECT_EQ(reader.count(), points.size());
    std::vector<MapPoint> blocks;
    int block_count = 0;
    for (std::span<const MapPoint> b = reader.next(); !b.empty(); b = reader.next()) {
      EXPECT_LE(b.size(), 65'536U);
      blocks.insert(blocks.end(), b.begin(), b.end());
      ++block_count;
    }
    EXPECT_EQ(block_count, 3);
    ASSERT_EQ(blocks.size(), whole.size());
    for (std::size_t i = 0; i < whole.size(); ++i) {
      ASSERT_EQ(blocks[i].x, whole[i].x) << i;
      ASSERT_EQ(blocks[i].y, whole[i].y) << i;
      ASSERT_EQ(blocks[i].z, whole[i].z) << i;
      ASSERT_EQ(blocks[i].intensity, whole[i].intensity) << i;
      ASSERT_EQ(blocks[i].time, whole[i].time) << i;
    }
    expect_same(read_map(f), points, 5e-4);
  }
}

// A bad point in a later block is named by its index in the file.
TEST_F(MapImport, ABadPointInALaterBlockIsNamedByItsIndexInTheFile) {
  std::vector<MapPoint> points(70'000);
  points[69'999].y = std::nan("");
  const auto f = file("late-nan.pcd");
  write_map(f, MapFormat::pcd, points);
  MapFileReader reader(f);
  EXPECT_EQ(reader.next().size(), 65'536U);
  try {
    reader.next();
    FAIL() << "read a NaN coordinate";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), f.string());
    EXPECT_EQ(e.key(), "point 69999");
  }
}

// A PLY with more vertex properties (doubles, colours) than ours, as other
// tools write it: only x y z (and intensity) are taken.
TEST_F(MapImport, OtherPlyVertexLayoutsRead) {
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\ncomment other tool\nelement vertex 2\nproperty uchar red\n"
      "property double x\nproperty double y\nproperty double z\nproperty ushort intensity\nend_header\n";
  const auto put = [&](auto v) { bytes.append(reinterpret_cast<const char*>(&v), sizeof v); };
  put(std::uint8_t{9}), put(1.5), put(-2.25), put(1e6 + 0.125), put(std::uint16_t{700});
  put(std::uint8_t{9}), put(0.0), put(0.0), put(0.0), put(std::uint16_t{1});
  const auto f = file("other.ply");
  std::ofstream(f, std::ios::binary) << bytes;
  const auto points = read_map(f);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[0].x, 1.5);
  EXPECT_EQ(points[0].y, -2.25);
  EXPECT_EQ(points[0].z, 1e6 + 0.125);
  EXPECT_EQ(points[0].intensity, 700.0f);
}

}  // namespace
}  // namespace adit::protocol
