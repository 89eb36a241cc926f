#pragma once
// An RGB image to draw the map's pictures in, written as PNG with libpng
// (http://www.libpng.org/pub/png/libpng-manual.txt), with the few drawing
// operations they need: pixels, thick lines, filled discs, and text in a
// 5 x 7 pixel font (digits, a few letters and signs) for scale bars.

#include <array>
#include <cstdint>
#include <filesystem>
#include <string_view>
#include <vector>

namespace adit::products {

using Rgb = std::array<std::uint8_t, 3>;

class RasterImage {
 public:
  RasterImage(int width, int height, Rgb background);
  int width() const { return width_; }
  int height() const { return height_; }
  void set(int x, int y, Rgb c);  // outside: ignored
  Rgb get(int x, int y) const;
  void line(double x0, double y0, double x1, double y1, Rgb c, int thickness);
  void disc(double x, double y, double radius, Rgb c);
  void rect(int x0, int y0, int x1, int y1, Rgb c);  // filled, inclusive
  // Text at (x, y) = top-left, each font pixel `scale` pixels; characters
  // outside the font are drawn as blanks. Returns the width drawn.
  int text(int x, int y, std::string_view s, Rgb c, int scale);
  // Throws adit::InputError naming the file. Returns its size in bytes.
  std::uintmax_t write_png(const std::filesystem::path& file) const;

 private:
  int width_, height_;
  std::vector<std::uint8_t> rgb_;
};

// A perceptually ordered colour map (viridis, by 9 control points) at t in 0..1.
Rgb viridis(double t);

}  // namespace adit::products
