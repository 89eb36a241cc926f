// products::encode_png: what libpng reads back is what was encoded, in both
// pixel formats; images it cannot make are refused.
#include <png.h>

#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "adit/products/png_encoder.hpp"

namespace adit::products {
namespace {

struct Decoded {
  png_uint_32 width = 0, height = 0;
  int colour = -1;
  std::vector<std::uint8_t> pixels;  // rows top to bottom
};

// libpng's simplified reader, from memory.
Decoded decode(const std::string& bytes, png_uint_32 format) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_memory(&image, bytes.data(), bytes.size()) == 0) throw std::runtime_error(image.message);
  Decoded d{image.width, image.height, static_cast<int>(image.format), {}};
  image.format = format;
  d.pixels.resize(PNG_IMAGE_SIZE(image));
  if (png_image_finish_read(&image, nullptr, d.pixels.data(), 0, nullptr) == 0) throw std::runtime_error(image.message);
  return d;
}

std::uint8_t pattern(int row, std::size_t byte) { return static_cast<std::uint8_t>(row * 31 + static_cast<int>(byte) * 7); }

TEST(PngEncoder, GreyAlphaRowsComeBackAsWritten) {
  const PngFormat format{5, 3, PngPixels::grey_alpha, 3, true};
  std::vector<int> asked;
  const std::string png = encode_png(format, [&](int row, std::span<std::uint8_t> pixels) {
    asked.push_back(row);
    ASSERT_EQ(pixels.size(), 10u);
    for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = pattern(row, i);
  });
  EXPECT_EQ(asked, (std::vector<int>{0, 1, 2}));
  const Decoded d = decode(png, PNG_FORMAT_GA);
  EXPECT_EQ(d.width, 5u);
  EXPECT_EQ(d.height, 3u);
  EXPECT_EQ(d.colour, PNG_FORMAT_GA);
  for (int row = 0; row < 3; ++row)
    for (std::size_t i = 0; i < 10; ++i) EXPECT_EQ(d.pixels[static_cast<std::size_t>(row) * 10 + i], pattern(row, i));
}

TEST(PngEncoder, RgbRowsComeBackAsWritten) {
  const std::string png = encode_png({4, 2, PngPixels::rgb}, [](int row, std::span<std::uint8_t> pixels) {
    for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = pattern(row, i);
  });
  const Decoded d = decode(png, PNG_FORMAT_RGB);
  EXPECT_EQ(d.colour, PNG_FORMAT_RGB);
  ASSERT_EQ(d.pixels.size(), 24u);
  for (int row = 0; row < 2; ++row)
    for (std::size_t i = 0; i < 12; ++i) EXPECT_EQ(d.pixels[static_cast<std::size_t>(row) * 12 + i], pattern(row, i));
}

TEST(PngEncoder, AnEmptyImageIsRefused) {
  const auto fill = [](int, std::span<std::uint8_t>) {};
  EXPECT_THROW(encode_png({0, 3, PngPixels::rgb}, fill), std::runtime_error);
  EXPECT_THROW(encode_png({3, -1, PngPixels::grey_alpha}, fill), std::runtime_error);
}

}  // namespace
}  // namespace adit::products
