// PNG encoding into memory. (png_encoder.hpp)
#include "adit/products/png_encoder.hpp"

#include <png.h>

#include <csetjmp>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

namespace adit::products {
namespace {

// libpng's output: appended to the string its io pointer names.
void append_to_string(png_structp png, png_bytep data, png_size_t length) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), length);
}

// Frees libpng's structures however encode_png leaves.
struct Writer {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  Writer() = default;
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;
  ~Writer() { png_destroy_write_struct(&png, &info); }
};

// libpng reports errors by longjmp back into this function: it owns nothing
// with a destructor (its caller does), so the jump skips none, and it is
// kept out of line so that no caller's objects join it.
[[gnu::noinline]] void write_png(const Writer& writer, const PngFormat& format,
                                 const std::function<void(int, std::span<std::uint8_t>)>& row,
                                 std::span<std::uint8_t> pixels, std::string& out) {
  png_structp png = writer.png;
  png_infop info = writer.info;
  if (setjmp(png_jmpbuf(png)))
    throw std::runtime_error(fmt::format("a {} x {} image as PNG: libpng failed", format.width, format.height));
  png_set_write_fn(png, &out, append_to_string, nullptr);
  if (format.compression_level >= 0) png_set_compression_level(png, format.compression_level);
  if (format.up_filter_only) png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_UP);
  png_set_IHDR(png, info, static_cast<png_uint_32>(format.width), static_cast<png_uint_32>(format.height), 8,
               format.pixels == PngPixels::rgb ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY_ALPHA, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int r = 0; r < format.height; ++r) {
    row(r, pixels);
    png_write_row(png, pixels.data());
  }
  png_write_end(png, nullptr);
}

}  // namespace

std::string encode_png(const PngFormat& format, const std::function<void(int, std::span<std::uint8_t>)>& row) {
  if (format.width <= 0 || format.height <= 0)
    throw std::runtime_error(fmt::format("a {} x {} image cannot be a PNG", format.width, format.height));
  const std::size_t channels = format.pixels == PngPixels::rgb ? 3 : 2;
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(format.width) * channels);
  std::string out;
  const Writer writer;
  if (writer.png == nullptr || writer.info == nullptr) throw std::runtime_error("libpng could not start");
  write_png(writer, format, row, pixels, out);
  return out;
}

}  // namespace adit::products
