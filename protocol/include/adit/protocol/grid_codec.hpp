#pragma once
// The live 2D grid's patches on the wire (grid_patch_t, docs/PROTOCOL.md):
// a patch's cells (int8 nav_msgs/OccupancyGrid values: -1 unknown, 0 free,
// 100 occupied; row-major, row 0 at the lowest y) as one zstd frame with its
// content checksum (UDP's 16-bit sum is weak). Grids compress well: a 128 ×
// 128 patch of a drift is 16 kB raw and typically well under 2 kB.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace adit {
class grid_patch_t;
}

namespace adit::protocol {

// A patch's cells at most this many per side: 200² bytes raw, which zstd's
// bound keeps inside one message's 48 000-byte payload.
inline constexpr int kMaxGridPatchCells = 200;

// Throws std::runtime_error when zstd cannot compress (out of memory).
std::vector<std::uint8_t> encode_grid_cells(std::span<const std::int8_t> cells);
// Fills `out` (exactly the patch's cells) from a frame; "" or what is wrong
// (not zstd, wrong size, a checksum or a cell value that is not -1, 0, 100).
std::string decode_grid_cells(std::span<const std::uint8_t> frame, std::span<std::int8_t> out);
// "" when the message's fields are usable (schema, resolution, patch size,
// data size), else what is wrong.
std::string grid_patch_problem(const grid_patch_t& patch);

}  // namespace adit::protocol
