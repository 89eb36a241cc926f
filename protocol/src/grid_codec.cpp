// The live grid's patch frames and checks. (grid_codec.hpp)
#include "adit/protocol/grid_codec.hpp"

#include <cmath>
#include <memory>
#include <stdexcept>

#include <fmt/format.h>
#include <zstd.h>

#include "adit/grid_patch_t.hpp"

namespace adit::protocol {

std::vector<std::uint8_t> encode_grid_cells(std::span<const std::int8_t> cells) {
  const std::unique_ptr<ZSTD_CCtx, decltype(&ZSTD_freeCCtx)> context(ZSTD_createCCtx(), &ZSTD_freeCCtx);
  if (!context) throw std::runtime_error("zstd: cannot create a compression context");
  ZSTD_CCtx_setParameter(context.get(), ZSTD_c_compressionLevel, 3);
  ZSTD_CCtx_setParameter(context.get(), ZSTD_c_checksumFlag, 1);
  std::vector<std::uint8_t> frame(ZSTD_compressBound(cells.size()));
  const std::size_t packed = ZSTD_compress2(context.get(), frame.data(), frame.size(), cells.data(), cells.size());
  if (ZSTD_isError(packed)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(packed));
  frame.resize(packed);
  return frame;
}

std::string decode_grid_cells(std::span<const std::uint8_t> frame, std::span<std::int8_t> out) {
  const unsigned long long content = ZSTD_getFrameContentSize(frame.data(), frame.size());
  if (content == ZSTD_CONTENTSIZE_UNKNOWN || content == ZSTD_CONTENTSIZE_ERROR) return "not a zstd frame of known size";
  if (content != out.size()) return fmt::format("the frame holds {} cells, a patch has {}", content, out.size());
  const std::size_t got = ZSTD_decompress(out.data(), out.size(), frame.data(), frame.size());
  if (ZSTD_isError(got)) return std::string("zstd: ") + ZSTD_getErrorName(got);
  if (got != out.size()) return "zstd frame is short";
  for (std::size_t i = 0; i < out.size(); ++i)
    if (out[i] != -1 && out[i] != 0 && out[i] != 100) return fmt::format("cell {} holds {}, not -1, 0 or 100", i, out[i]);
  return {};
}

std::string grid_patch_problem(const grid_patch_t& patch) {
  if (patch.schema != 1) return fmt::format("schema {} (this build reads 1)", patch.schema);
  if (!std::isfinite(patch.resolution_m) || patch.resolution_m <= 0.0F)
    return fmt::format("resolution {} m is not positive", patch.resolution_m);
  if (patch.patch_cells < 1 || patch.patch_cells > kMaxGridPatchCells)
    return fmt::format("patch of {} cells a side (1 .. {})", patch.patch_cells, kMaxGridPatchCells);
  if (patch.size < 0 || static_cast<std::size_t>(patch.size) != patch.data.size())
    return fmt::format("size {} but {} bytes of data", patch.size, patch.data.size());
  if (patch.version < 1) return fmt::format("version {} (from 1)", patch.version);
  return {};
}

}  // namespace adit::protocol
