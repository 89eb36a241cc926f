#pragma once
// A client's copy of the live 2D grid: the patches received (grid_patch_t),
// the newest version of each, and the whole grid as one image for a viewer
// or a ROS map_server file. A message of another session starts a new grid;
// one of another resolution or patch size than the grid held is refused.

#include <cstdint>
#include <map>
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

  GridImage image() const;
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
  std::string session_id_;
  float resolution_m_ = 0.0F;
  std::int32_t patch_cells_ = 0;
  std::map<std::pair<std::int32_t, std::int32_t>, Patch> patches_;
  std::int64_t version_sum_ = 0;
  GridMosaicCounts counts_;
};

}  // namespace adit::protocol
