#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "adit/common/error.hpp"
#include "adit/products/grid_io.hpp"

namespace adit::products {
namespace {

std::filesystem::path temp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("adit_test_grid_io_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

Grid2d sample_grid() {
  Grid2d g;
  g.resolution_m = 0.05;
  g.origin_x = -1.25;
  g.origin_y = 2.5;
  g.width = 7;
  g.height = 4;
  g.cells.assign(28, kUnknown);
  g.at(0, 0) = kOccupied;  // lower-left: the image's last row
  g.at(6, 3) = kFree;
  g.at(3, 1) = kOccupied;
  return g;
}

TEST(GridIo, WritesMapServerFilesAndReadsThemBack) {
  const auto dir = temp_dir("roundtrip");
  const Grid2d g = sample_grid();
  const std::uintmax_t bytes = write_grid(dir / "grid", g);
  EXPECT_EQ(bytes, std::filesystem::file_size(dir / "grid.pgm") + std::filesystem::file_size(dir / "grid.yaml"));
  const Grid2d back = read_grid(dir / "grid.yaml");
  EXPECT_EQ(back.width, 7);
  EXPECT_EQ(back.height, 4);
  EXPECT_DOUBLE_EQ(back.resolution_m, 0.05);
  EXPECT_NEAR(back.origin_x, -1.25, 1e-9);
  EXPECT_NEAR(back.origin_y, 2.5, 1e-9);
  EXPECT_EQ(back.cells, g.cells);
  // map_server's convention: the image's first row is the top (highest y); occupied black.
  std::ifstream in(dir / "grid.pgm", std::ios::binary);
  const std::string pgm((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(static_cast<unsigned char>(pgm[pgm.size() - 7]), 0);      // (0, 0): last row, first column
  EXPECT_EQ(static_cast<unsigned char>(pgm[pgm.size() - 28 + 6]), 254);  // (6, 3): first row, last column
}

TEST(GridIo, BadFilesNameTheFileLineAndKey) {
  const std::string pgm = "P5\n2 1\n255\n\xfe\x00";
  try {
    parse_grid("image: g.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nfoo: 1\n", "g.yaml", pgm, "g.pgm");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "g.yaml:4");
    EXPECT_EQ(e.key(), "foo");
  }
  try {
    parse_grid("image: g.pgm\nresolution: -1\norigin: [0, 0, 0]\n", "g.yaml", pgm, "g.pgm");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), "g.yaml:2");
    EXPECT_EQ(e.key(), "resolution");
  }
  EXPECT_THROW(parse_grid("image: g.pgm\nresolution: 0.05\norigin: [0, 0]\n", "g.yaml", pgm, "g.pgm"), InputError);
  EXPECT_THROW(parse_grid("image: g.pgm\norigin: [0, 0, 0]\n", "g.yaml", pgm, "g.pgm"), InputError);
  EXPECT_THROW(parse_grid("image: g.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n", "g.yaml", "P5\n3 1\n255\n\x01", "g.pgm"),
               InputError);  // truncated
  EXPECT_THROW(parse_grid("image: g.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n", "g.yaml", "P2\n1 1\n255\n0", "g.pgm"),
               InputError);  // ASCII PGM
}

}  // namespace
}  // namespace adit::products
