// Fuzzes the live grid's receiving side: the bytes as a grid_patch_t message
// fed to a client's mosaic (checks, then decodes the patch's zstd frame), and
// the same bytes as a bare frame of cells. Bad input must be refused, never crash.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "adit/grid_patch_t.hpp"
#include "adit/protocol/checked_decode.hpp"
#include "adit/protocol/grid_codec.hpp"
#include "adit/protocol/grid_mosaic.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  adit::grid_patch_t patch;
  if (adit::protocol::checked_decode(data, size, patch)) {
    adit::protocol::GridMosaic mosaic;
    (void)mosaic.accept(patch);
    if (patch.version < std::numeric_limits<std::int32_t>::max()) {  // a newer version of the same patch
      patch.version += 1;
      (void)mosaic.accept(patch);
    }
    if (mosaic.patch_count() > 0) (void)mosaic.image();
  }
  std::vector<std::int8_t> cells(16 * 16);
  (void)adit::protocol::decode_grid_cells(std::span(data, size), cells);
  return 0;
}
