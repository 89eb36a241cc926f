#pragma once
// A client's copy of the live 2D grid: the patches received (grid_patch_t),
// the newest version of each, and the whole grid as one image for a viewer
// or a ROS map_server file. A message of another session starts a new grid;
// one of another resolution or patch size than the grid held is refused.

#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace adit {
class grid_patch_t;
}

namespace adit::protocol {

// The grid over the patches' bounding box; cells row-major, row 0 at the
// lowest y, -1 where no patch is.
struct GridImage {
  double resolution_m = 0.0;  // the patches' (a float) rounded to 1 µm
  double origin_x = 0.0, origin_y = 0.0;  // the lower-left corner of cell (0, 0), map frame
  int width = 0, height = 0;
  std::vector<std::int8_t> cells;
};

// A square of block_patches × block_patches patches, aligned on multiples of
// block_patches: what a viewer fetches and redraws as one piece, so a change
// costs one block and no image grows past a GPU's largest texture.
struct GridBlock {
  std::int32_t x = 0, y = 0;   // block (x, y) holds patches [x·n, (x+1)·n) × [y·n, (y+1)·n), n = block_patches
  std::int64_t version = 0;    // the sum of its patches' versions
  std::size_t patches = 0;
};

struct GridMosaicCounts {
  std::uint64_t accepted = 0;  // a new patch or a newer version
  std::uint64_t stale = 0;     // a version already held (refresh) or older
  std::uint64_t refused = 0;   // malformed: see accept()'s answer
};

class GridMosaic {
 public:
  // "" when the message was taken (or was stale), else why it was refused.
  std::string accept(const grid_patch_t& patch);
  // The same for a patch's cells at hand (the daemon's own grid at the end of
  // a session): `cells` holds patch_cells² values.
  std::string put(const std::string& session_id, float resolution_m, std::int32_t patch_cells, std::int32_t x,
                  std::int32_t y, std::int32_t version, std::vector<std::int8_t> cells);

  // The patches' bounding box as one image.
  GridImage image() const;
  // image()'s size and place, without its cells.
  GridImage extent() const;
  // The blocks that hold a patch, in (x, y) order. block_patches is a power
  // of two, so every block's patches lie within int32.
  std::vector<GridBlock> blocks(std::int32_t block_patches) const;
  // Block (x, y) as blocks() lists it, walking only its own patches; none
  // when it holds no patch.
  std::optional<GridBlock> block(std::int32_t block_patches, std::int32_t x, std::int32_t y) const;
  // Block (x, y) as one image over the bounding box of its patches, -1 where
  // no patch is (an image of no cells when the block holds none).
  GridImage block_image(std::int32_t block_patches, std::int32_t x, std::int32_t y) const;
  std::int32_t patch_cells() const { return patch_cells_; }
  const std::string& session_id() const { return session_id_; }
  std::size_t patch_count() const { return patches_.size(); }
  // The sum of the patches' versions: it grows with every change within a
  // session, and any copy holding the same patches gives the same number.
  std::int64_t version_sum() const { return version_sum_; }
  const GridMosaicCounts& counts() const { return counts_; }

 private:
  struct Patch {
    std::int32_t version = 0;
    std::vector<std::int8_t> cells;
  };
  // Patches [min_x, max_x] × [min_y, max_y] as one image, with its cells or without.
  GridImage image_of(std::int32_t min_x, std::int32_t min_y, std::int32_t max_x, std::int32_t max_y,
                     bool cells) const;
  // image_of() over the patches' bounding box.
  GridImage bounding_image(bool cells) const;
  // Block (x, y)'s patches: their bounding box, version sum and count.
  struct BlockSpan {
    std::int32_t min_x = std::numeric_limits<std::int32_t>::max(), min_y = std::numeric_limits<std::int32_t>::max();
    std::int32_t max_x = std::numeric_limits<std::int32_t>::min(), max_y = std::numeric_limits<std::int32_t>::min();
    GridBlock block;
  };
  BlockSpan span_of_block(std::int32_t block_patches, std::int32_t x, std::int32_t y) const;

  std::string session_id_;
  float resolution_m_ = 0.0F;
  std::int32_t patch_cells_ = 0;
  std::map<std::pair<std::int32_t, std::int32_t>, Patch> patches_;
  std::int64_t version_sum_ = 0;
  GridMosaicCounts counts_;
};

}  // namespace adit::protocol
