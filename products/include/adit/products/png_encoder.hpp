#pragma once
// PNG encoding with libpng (http://www.libpng.org/pub/png/libpng-manual.txt),
// row by row into memory: the one PNG writer of the project (the session's
// pictures, adit console's live grid). Rows are asked for one at a time, so
// no whole-image pixel buffer is made besides the caller's own data.

#include <cstdint>
#include <functional>
#include <span>
#include <string>

namespace adit::products {

enum class PngPixels { grey_alpha, rgb };  // 8 bits per channel

struct PngFormat {
  int width = 0;
  int height = 0;
  PngPixels pixels = PngPixels::rgb;
  int compression_level = -1;  // zlib's 0..9; -1 its default (6)
  bool up_filter_only = false; // the UP filter alone: fast, and suits rows that mostly repeat the one above
};

// `row(r, pixels)` writes image row r (0 = the top) into `pixels`
// (width × channels bytes). Throws std::runtime_error when libpng fails.
std::string encode_png(const PngFormat& format, const std::function<void(int, std::span<std::uint8_t>)>& row);

}  // namespace adit::products
