// A client's copy of the live 2D grid. (grid_mosaic.hpp)
#include "adit/protocol/grid_mosaic.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "adit/grid_patch_t.hpp"
#include "adit/protocol/grid_codec.hpp"

namespace adit::protocol {

std::string GridMosaic::accept(const grid_patch_t& patch) {
  if (std::string problem = grid_patch_problem(patch); !problem.empty()) {
    ++counts_.refused;
    return problem;
  }
  // A refresh of a version held: nothing to decode.
  if (patch.session_id == session_id_) {
    const auto held = patches_.find({patch.patch_x, patch.patch_y});
    if (held != patches_.end() && patch.version <= held->second.version) {
      ++counts_.stale;
      return {};
    }
  }
  std::vector<std::int8_t> cells(static_cast<std::size_t>(patch.patch_cells) * static_cast<std::size_t>(patch.patch_cells));
  if (const std::string problem = decode_grid_cells(patch.data, cells); !problem.empty()) {
    ++counts_.refused;
    return fmt::format("patch ({}, {}) version {}: {}", patch.patch_x, patch.patch_y, patch.version, problem);
  }
  return put(patch.session_id, patch.resolution_m, patch.patch_cells, patch.patch_x, patch.patch_y, patch.version,
             std::move(cells));
}

std::string GridMosaic::put(const std::string& session_id, float resolution_m, std::int32_t patch_cells,
                            std::int32_t x, std::int32_t y, std::int32_t version, std::vector<std::int8_t> cells) {
  if (session_id != session_id_ || patches_.empty()) {
    if (session_id != session_id_) {
      patches_.clear();
      version_sum_ = 0;
    }
    session_id_ = session_id;
    resolution_m_ = resolution_m;
    patch_cells_ = patch_cells;
  }
  std::string problem;
  if (resolution_m != resolution_m_ || patch_cells != patch_cells_)
    problem = fmt::format("a patch of {} cells at {} m in a grid of {} cells at {} m", patch_cells, resolution_m,
                          patch_cells_, resolution_m_);
  else if (cells.size() != static_cast<std::size_t>(patch_cells) * static_cast<std::size_t>(patch_cells))
    problem = fmt::format("patch ({}, {}): {} cells for {} a side", x, y, cells.size(), patch_cells);
  if (!problem.empty()) {
    ++counts_.refused;
    return problem;
  }
  Patch& held = patches_[{x, y}];
  if (version <= held.version) {
    ++counts_.stale;
    return {};
  }
  version_sum_ += version - held.version;
  held = {version, std::move(cells)};
  ++counts_.accepted;
  return {};
}

GridImage GridMosaic::image() const { return bounding_image(true); }

GridImage GridMosaic::extent() const { return bounding_image(false); }

GridImage GridMosaic::bounding_image(bool cells) const {
  if (patches_.empty()) return {};
  std::int32_t min_x = std::numeric_limits<std::int32_t>::max(), min_y = min_x;
  std::int32_t max_x = std::numeric_limits<std::int32_t>::min(), max_y = max_x;
  for (const auto& [coord, patch] : patches_) {
    min_x = std::min(min_x, coord.first);
    max_x = std::max(max_x, coord.first);
    min_y = std::min(min_y, coord.second);
    max_y = std::max(max_y, coord.second);
  }
  return image_of(min_x, min_y, max_x, max_y, cells);
}

namespace {

// The block of patch coordinate c: floor(c / n), for negative c too.
std::int32_t block_of(std::int32_t c, std::int32_t n) { return c >= 0 ? c / n : -((-c + n - 1) / n); }

}  // namespace

std::vector<GridBlock> GridMosaic::blocks(std::int32_t block_patches) const {
  std::map<std::pair<std::int32_t, std::int32_t>, GridBlock> blocks;
  for (const auto& [coord, patch] : patches_) {
    const std::int32_t bx = block_of(coord.first, block_patches), by = block_of(coord.second, block_patches);
    GridBlock& b = blocks[{bx, by}];
    b.x = bx;
    b.y = by;
    b.version += patch.version;
    ++b.patches;
  }
  std::vector<GridBlock> out;
  out.reserve(blocks.size());
  for (const auto& [coord, block] : blocks) out.push_back(block);
  return out;
}

GridMosaic::BlockSpan GridMosaic::span_of_block(std::int32_t block_patches, std::int32_t x, std::int32_t y) const {
  BlockSpan span;
  span.block.x = x;
  span.block.y = y;
  const std::int32_t x0 = x * block_patches, y0 = y * block_patches;
  const std::int32_t x1 = x0 + (block_patches - 1), y1 = y0 + (block_patches - 1);
  for (auto it = patches_.lower_bound({x0, std::numeric_limits<std::int32_t>::min()});
       it != patches_.end() && it->first.first <= x1; ++it) {
    const auto [px, py] = it->first;
    if (py < y0 || py > y1) continue;
    span.min_x = std::min(span.min_x, px);
    span.max_x = std::max(span.max_x, px);
    span.min_y = std::min(span.min_y, py);
    span.max_y = std::max(span.max_y, py);
    span.block.version += it->second.version;
    ++span.block.patches;
  }
  return span;
}

std::optional<GridBlock> GridMosaic::block(std::int32_t block_patches, std::int32_t x, std::int32_t y) const {
  const BlockSpan span = span_of_block(block_patches, x, y);
  if (span.block.patches == 0) return std::nullopt;
  return span.block;
}

GridImage GridMosaic::block_image(std::int32_t block_patches, std::int32_t x, std::int32_t y) const {
  // The bounding box of the block's patches: a block at the grid's edge is
  // not padded to its full size with unknown cells (a texture upload saved).
  const BlockSpan span = span_of_block(block_patches, x, y);
  if (span.block.patches == 0) return {};
  return image_of(span.min_x, span.min_y, span.max_x, span.max_y, true);
}

GridImage GridMosaic::image_of(std::int32_t min_x, std::int32_t min_y, std::int32_t max_x, std::int32_t max_y,
                               bool cells) const {
  GridImage image;
  const int n = patch_cells_;
  // The message's float, to the micrometre: 0.05 is written 0.05, not 0.0500000007.
  image.resolution_m = std::round(static_cast<double>(resolution_m_) * 1e6) / 1e6;
  image.origin_x = static_cast<double>(min_x) * n * image.resolution_m;
  image.origin_y = static_cast<double>(min_y) * n * image.resolution_m;
  image.width = (max_x - min_x + 1) * n;
  image.height = (max_y - min_y + 1) * n;
  if (!cells) return image;
  image.cells.assign(static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height), -1);
  for (auto it = patches_.lower_bound({min_x, std::numeric_limits<std::int32_t>::min()});
       it != patches_.end() && it->first.first <= max_x; ++it) {
    const auto& [coord, patch] = *it;
    if (coord.second < min_y || coord.second > max_y) continue;
    const int col0 = (coord.first - min_x) * n;
    const int row0 = (coord.second - min_y) * n;
    for (int r = 0; r < n; ++r)
      std::copy_n(patch.cells.begin() + static_cast<std::ptrdiff_t>(r) * n, n,
                  image.cells.begin() + static_cast<std::ptrdiff_t>(row0 + r) * image.width + col0);
  }
  return image;
}

}  // namespace adit::protocol
