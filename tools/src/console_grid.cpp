// adit console: the live 2D grid as a PNG. (console_grid.hpp)
#include "console_grid.hpp"

#include <algorithm>

#include "adit/products/png_encoder.hpp"

namespace adit::tools::console {

// Speed over size: a new grid can come every second (1280 x 1024 cells of
// synthetic corridors: about 8 ms and 16 kB on the 2-core build machine; zlib's
// default level 6 and all filters, 37 ms and 5 kB). The UP filter suits a
// grid's rows, which mostly repeat the row below.
constexpr int kCompressionLevel = 3;

std::int32_t grid_block_patches(std::int32_t patch_cells) {
  std::int32_t n = 1;
  while (2 * n * std::max(patch_cells, 1) <= kGridBlockCells) n *= 2;
  return n;
}

// nav_msgs/OccupancyGrid: -1 unknown, 0..100 the occupancy in percent. Any
// other negative value is unknown, anything above 100 is occupied.
std::uint8_t grid_grey(std::int8_t cell) {
  if (cell < 0) return 0;
  const int v = std::min<int>(cell, 100);
  return static_cast<std::uint8_t>(255 - (255 * v + 50) / 100);  // 255 - round(2.55 v), in integers
}

std::uint8_t grid_alpha(std::int8_t cell) { return cell < 0 ? 0 : 255; }

// Row by row: no whole-image buffer besides the grid itself, so encoding a
// grid every second does not leave megabytes in each server thread's heap.
// The image's top row is the grid's last (the highest y).
std::string grid_png(const protocol::GridImage& grid) {
  const products::PngFormat format{grid.width, grid.height, products::PngPixels::grey_alpha, kCompressionLevel, true};
  return products::encode_png(format, [&grid](int row, std::span<std::uint8_t> pixels) {
    const auto* cells = grid.cells.data() + static_cast<std::ptrdiff_t>(grid.height - 1 - row) * grid.width;
    for (int col = 0; col < grid.width; ++col) {
      pixels[2 * static_cast<std::size_t>(col)] = grid_grey(cells[col]);
      pixels[2 * static_cast<std::size_t>(col) + 1] = grid_alpha(cells[col]);
    }
  });
}

GridBytes grid_bytes(const protocol::GridImage& image, std::string session, std::int64_t version,
                     std::size_t patches) {
  return {.session = std::move(session),
          .version = version,
          .patches = patches,
          .resolution_m = image.resolution_m,
          .origin_x = image.origin_x,
          .origin_y = image.origin_y,
          .width = image.width,
          .height = image.height,
          .png = grid_png(image)};
}

}  // namespace adit::tools::console
