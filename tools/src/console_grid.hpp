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

// The grid, or one block of it, as a browser gets it from GET /api/grid or
// GET /api/grid/block (docs/CONSOLE.md).
struct GridBytes {
  std::string session;
  std::int64_t version = 0;   // the sum of its patches' versions: grows with every change
  std::size_t patches = 0;
  double resolution_m = 0.0;
  double origin_x = 0.0, origin_y = 0.0;  // the lower-left corner of the lowest row's first cell, map frame
  int width = 0, height = 0;
  std::string png;
};

// The page draws the grid in blocks of about kGridBlockCells cells a side
// (protocol::GridBlock): a change re-sends and re-uploads its block only, and
// no texture passes the 4096 texels a side some GPUs allow.
inline constexpr std::int32_t kGridBlockCells = 1024;
// Patches per block side: the largest power of two with at most
// kGridBlockCells cells, at least one patch.
std::int32_t grid_block_patches(std::int32_t patch_cells);

// The pixel a cell is written as: {grey, alpha}.
std::uint8_t grid_grey(std::int8_t cell);
std::uint8_t grid_alpha(std::int8_t cell);

// The image as a PNG. Throws std::runtime_error with libpng's message when it
// cannot encode.
std::string grid_png(const protocol::GridImage& image);
// The image as a browser gets it: where it lies and its PNG (grid_png).
GridBytes grid_bytes(const protocol::GridImage& image, std::string session, std::int64_t version,
                     std::size_t patches);

}  // namespace adit::tools::console
