#pragma once
// adit console: the live 2D grid for a browser. The payload's grid_patch_t
// messages, assembled by protocol::GridMosaic, go to the page as one PNG
// (8-bit grey + alpha, libpng): a browser decodes it by itself and a person
// can open it. Each cell is one pixel, the top row the
// highest y (as an image, and as ROS map_server's PGM):
//   unknown (-1)   grey 0, alpha 0 (transparent)
//   0..100         grey 255 - round(2.55 v), alpha 255 (free white, occupied black)
// The grey is exact both ways: v = round((255 - grey) / 2.55).

#include <cstdint>
#include <string>

#include "adit/protocol/grid_mosaic.hpp"

namespace adit::tools::console {

// The grid as a browser gets it from GET /api/grid (docs/CONSOLE.md).
struct GridBytes {
  std::string session;
  std::int64_t version = 0;   // the sum of the patches' versions: grows with every change
  std::size_t patches = 0;
  double resolution_m = 0.0;
  double origin_x = 0.0, origin_y = 0.0;  // the lower-left corner of the lowest row's first cell, map frame
  int width = 0, height = 0;
  std::string png;
};

// The pixel a cell is written as: {grey, alpha}.
std::uint8_t grid_grey(std::int8_t cell);
std::uint8_t grid_alpha(std::int8_t cell);

// The image as a PNG. Throws std::runtime_error with libpng's message when it
// cannot encode.
std::string grid_png(const protocol::GridImage& image);

}  // namespace adit::tools::console
