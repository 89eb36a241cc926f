// The live grid's patches: coded, checked and assembled into one image.
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "adit/grid_patch_t.hpp"
#include "adit/protocol/grid_codec.hpp"
#include "adit/protocol/grid_mosaic.hpp"

namespace adit::protocol {
namespace {

constexpr int kCells = 4;

grid_patch_t patch_message(std::string session, int x, int y, int version, std::int8_t fill) {
  grid_patch_t m;
  m.utime = 1;
  m.schema = 1;
  m.payload_id = "rig1";
  m.session_id = std::move(session);
  m.resolution_m = 0.5F;
  m.patch_cells = kCells;
  m.patch_x = x;
  m.patch_y = y;
  m.version = version;
  m.n_patches = 1;
  std::vector<std::int8_t> cells(kCells * kCells, fill);
  cells[0] = 100;  // the lowest row's first cell
  const std::vector<std::uint8_t> frame = encode_grid_cells(cells);
  m.data.assign(frame.begin(), frame.end());
  m.size = static_cast<std::int32_t>(m.data.size());
  return m;
}

TEST(GridCodec, CellsComeBackAsTheyWentAndBadFramesSayWhy) {
  std::vector<std::int8_t> cells(128 * 128, -1);
  for (std::size_t i = 0; i < cells.size(); i += 7) cells[i] = (i % 2 == 0) ? 0 : 100;
  const std::vector<std::uint8_t> frame = encode_grid_cells(cells);
  EXPECT_LT(frame.size(), cells.size() / 4);
  std::vector<std::int8_t> back(cells.size());
  EXPECT_EQ(decode_grid_cells(frame, back), "");
  EXPECT_EQ(back, cells);

  std::vector<std::int8_t> small(100);
  EXPECT_NE(decode_grid_cells(frame, small).find("a patch has 100"), std::string::npos);
  std::vector<std::uint8_t> flipped = frame;
  flipped[flipped.size() / 2] ^= 0x5A;
  EXPECT_NE(decode_grid_cells(flipped, back), "");
  const std::vector<std::int8_t> odd(16, 50);
  std::vector<std::int8_t> odd_back(16);
  EXPECT_NE(decode_grid_cells(encode_grid_cells(odd), odd_back).find("not -1, 0 or 100"), std::string::npos);
  const std::vector<std::uint8_t> junk{1, 2, 3};
  EXPECT_NE(decode_grid_cells(junk, back), "");
}

TEST(GridMosaic, KeepsTheNewestVersionOfEachPatchAndDrawsThemInPlace) {
  GridMosaic mosaic;
  EXPECT_EQ(mosaic.accept(patch_message("s1", 0, 0, 1, -1)), "");
  EXPECT_EQ(mosaic.accept(patch_message("s1", -1, 1, 1, 0)), "");
  EXPECT_EQ(mosaic.accept(patch_message("s1", 0, 0, 2, 0)), "");   // newer
  EXPECT_EQ(mosaic.accept(patch_message("s1", 0, 0, 1, 100)), "");  // older: ignored
  EXPECT_EQ(mosaic.counts().accepted, 3U);
  EXPECT_EQ(mosaic.counts().stale, 1U);
  const GridImage image = mosaic.image();
  EXPECT_EQ(image.width, 2 * kCells);
  EXPECT_EQ(image.height, 2 * kCells);
  EXPECT_DOUBLE_EQ(image.origin_x, -2.0);
  EXPECT_DOUBLE_EQ(image.origin_y, 0.0);
  const auto at = [&](int col, int row) { return image.cells[static_cast<std::size_t>(row * image.width + col)]; };
  EXPECT_EQ(at(kCells, 0), 100);       // patch (0, 0)'s first cell
  EXPECT_EQ(at(kCells + 1, 0), 0);     // patch (0, 0) version 2: free
  EXPECT_EQ(at(0, kCells), 100);       // patch (-1, 1)
  EXPECT_EQ(at(1, kCells + 1), 0);
  EXPECT_EQ(at(0, 0), -1);             // patch (-1, 0) never came
  EXPECT_EQ(at(kCells, kCells), -1);   // nor (0, 1)
}

// Blocks of 2 × 2 patches: patch -1 is in block -1, patches 0 and 1 in block 0.
TEST(GridMosaic, BlocksHoldTheirPatchesInPlaceAndSumTheirVersions) {
  GridMosaic mosaic;
  EXPECT_TRUE(mosaic.blocks(2).empty());
  EXPECT_TRUE(mosaic.block_image(2, 0, 0).cells.empty());
  ASSERT_EQ(mosaic.accept(patch_message("s1", -1, 0, 3, 0)), "");
  ASSERT_EQ(mosaic.accept(patch_message("s1", 0, 0, 1, 0)), "");
  ASSERT_EQ(mosaic.accept(patch_message("s1", 1, 1, 2, -1)), "");
  ASSERT_EQ(mosaic.accept(patch_message("s1", 2, -3, 1, 0)), "");
  const std::vector<GridBlock> blocks = mosaic.blocks(2);
  ASSERT_EQ(blocks.size(), 3U);
  EXPECT_EQ(blocks[0].x, -1);
  EXPECT_EQ(blocks[0].y, 0);
  EXPECT_EQ(blocks[0].version, 3);
  EXPECT_EQ(blocks[1].x, 0);
  EXPECT_EQ(blocks[1].y, 0);
  EXPECT_EQ(blocks[1].version, 3) << "patches (0, 0) version 1 and (1, 1) version 2";
  EXPECT_EQ(blocks[1].patches, 2U);
  EXPECT_EQ(blocks[2].x, 1);
  EXPECT_EQ(blocks[2].y, -2) << "patch y -3 lies in block -2 (patches -4 and -3)";

  const GridImage b = mosaic.block_image(2, 0, 0);
  ASSERT_EQ(b.width, 2 * kCells);
  ASSERT_EQ(b.height, 2 * kCells);
  EXPECT_DOUBLE_EQ(b.origin_x, 0.0);
  EXPECT_DOUBLE_EQ(b.origin_y, 0.0);
  const auto at = [&](const GridImage& image, int col, int row) {
    return image.cells[static_cast<std::size_t>(row * image.width + col)];
  };
  EXPECT_EQ(at(b, 0, 0), 100);                    // patch (0, 0)'s first cell
  EXPECT_EQ(at(b, 1, 0), 0);
  EXPECT_EQ(at(b, kCells, kCells), 100);          // patch (1, 1)'s first cell
  EXPECT_EQ(at(b, kCells + 1, kCells), -1);       // patch (1, 1): unknown
  EXPECT_EQ(at(b, kCells, 0), -1);                // patch (1, 0) never came
  // A block is cut to its patches' bounding box: block -1 holds patch (-1, 0) only.
  const GridImage left = mosaic.block_image(2, -1, 0);
  EXPECT_DOUBLE_EQ(left.origin_x, -2.0);          // patch -1 at 4 cells of 0.5 m
  EXPECT_EQ(left.width, kCells);
  EXPECT_EQ(left.height, kCells);
  EXPECT_EQ(at(left, 0, 0), 100);                 // patch (-1, 0)'s first cell
  EXPECT_TRUE(mosaic.block_image(2, 5, 5).cells.empty()) << "a block without patches";
  // One block alone, as the list gives it; none where no patch is.
  for (const GridBlock& listed : blocks) {
    const std::optional<GridBlock> one = mosaic.block(2, listed.x, listed.y);
    ASSERT_TRUE(one.has_value());
    EXPECT_EQ(one->x, listed.x);
    EXPECT_EQ(one->y, listed.y);
    EXPECT_EQ(one->version, listed.version);
    EXPECT_EQ(one->patches, listed.patches);
  }
  EXPECT_FALSE(mosaic.block(2, 5, 5).has_value());
  EXPECT_FALSE(mosaic.block(2, 1, 0).has_value()) << "beside patch (2, -3)'s block, not in it";

  // Every block's cells are the whole image's there.
  const GridImage whole = mosaic.image();
  for (const GridBlock& block : blocks) {
    const GridImage part = mosaic.block_image(2, block.x, block.y);
    const int col0 = static_cast<int>(std::lround((part.origin_x - whole.origin_x) / whole.resolution_m));
    const int row0 = static_cast<int>(std::lround((part.origin_y - whole.origin_y) / whole.resolution_m));
    for (int row = 0; row < part.height; ++row)
      for (int col = 0; col < part.width; ++col) {
        const int c = col0 + col, r = row0 + row;
        if (c < 0 || r < 0 || c >= whole.width || r >= whole.height) {
          EXPECT_EQ(at(part, col, row), -1);
          continue;
        }
        ASSERT_EQ(at(part, col, row), at(whole, c, r)) << "block (" << block.x << ", " << block.y << ")";
      }
  }
}

TEST(GridMosaic, RefusesMalformedPatchesAndStartsAgainForANewSession) {
  GridMosaic mosaic;
  ASSERT_EQ(mosaic.accept(patch_message("s1", 0, 0, 1, 0)), "");
  grid_patch_t bad = patch_message("s1", 1, 0, 1, 0);
  bad.resolution_m = 0.25F;
  EXPECT_NE(mosaic.accept(bad).find("in a grid of 4 cells at 0.5 m"), std::string::npos);
  bad = patch_message("s1", 1, 0, 1, 0);
  bad.size = 3;
  EXPECT_NE(mosaic.accept(bad).find("bytes of data"), std::string::npos);
  bad = patch_message("s1", 1, 0, 1, 0);
  bad.data[bad.data.size() / 2] ^= 0x33;
  EXPECT_NE(mosaic.accept(bad).find("patch (1, 0) version 1"), std::string::npos);
  bad = patch_message("s1", 1, 0, 1, 0);
  bad.patch_cells = kMaxGridPatchCells + 1;
  EXPECT_NE(mosaic.accept(bad), "");
  EXPECT_EQ(mosaic.counts().refused, 4U);
  EXPECT_EQ(mosaic.patch_count(), 1U);
  EXPECT_EQ(mosaic.accept(patch_message("s2", 5, 5, 1, 0)), "");
  EXPECT_EQ(mosaic.session_id(), "s2");
  EXPECT_EQ(mosaic.patch_count(), 1U);
  EXPECT_DOUBLE_EQ(mosaic.image().origin_x, 10.0);
}

}  // namespace
}  // namespace adit::protocol
