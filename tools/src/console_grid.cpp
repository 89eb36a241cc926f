// adit console: the live 2D grid as a PNG. (console_grid.hpp)
#include "console_grid.hpp"

#include <png.h>

#include <algorithm>
#include <csetjmp>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

namespace adit::tools::console {

// Speed over size: a new grid can come every second (1280 x 1024 cells of
// synthetic corridors: about 8 ms and 16 kB on the 2-core build machine; zlib's
// default level 6 and all filters, 37 ms and 5 kB). The UP filter suits a
// grid's rows, which mostly repeat the row below.
constexpr int kCompressionLevel = 3;

// nav_msgs/OccupancyGrid: -1 unknown, 0..100 the occupancy in percent. Any
// other negative value is unknown, anything above 100 is occupied.
std::uint8_t grid_grey(std::int8_t cell) {
  if (cell < 0) return 0;
  const int v = std::min<int>(cell, 100);
  return static_cast<std::uint8_t>(255 - (255 * v + 50) / 100);  // 255 - round(2.55 v), in integers
}

std::uint8_t grid_alpha(std::int8_t cell) { return cell < 0 ? 0 : 255; }

namespace {

// libpng's output: appended to the string its io pointer names.
void append_to_string(png_structp png, png_bytep data, png_size_t length) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), length);
}

// The cells of `grid` row `row` as grey + alpha pixels.
void fill_row(const protocol::GridImage& grid, int row, std::vector<std::uint8_t>& pixels) {
  const auto* cells = grid.cells.data() + static_cast<std::ptrdiff_t>(row) * grid.width;
  for (int col = 0; col < grid.width; ++col) {
    pixels[2 * static_cast<std::size_t>(col)] = grid_grey(cells[col]);
    pixels[2 * static_cast<std::size_t>(col) + 1] = grid_alpha(cells[col]);
  }
}

}  // namespace

// Row by row (libpng's own API, not the simplified one): no whole-image
// buffers besides the grid itself, so encoding a grid every second does not
// leave megabytes in each server thread's heap.
std::string grid_png(const protocol::GridImage& grid) {
  std::string out;
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(grid.width) * 2);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("libpng could not start");
  }
  // libpng reports errors by longjmp: nothing with a destructor is made between here and the end.
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error(fmt::format("the grid ({} x {}) as PNG: libpng failed", grid.width, grid.height));
  }
  png_set_write_fn(png, &out, append_to_string, nullptr);
  png_set_compression_level(png, kCompressionLevel);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_UP);
  png_set_IHDR(png, info, static_cast<png_uint_32>(grid.width), static_cast<png_uint_32>(grid.height), 8,
               PNG_COLOR_TYPE_GRAY_ALPHA, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  // The image's top row is the grid's last (the highest y).
  for (int row = grid.height - 1; row >= 0; --row) {
    fill_row(grid, row, pixels);
    png_write_row(png, pixels.data());
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

}  // namespace adit::tools::console
