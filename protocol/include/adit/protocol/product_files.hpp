#pragma once
// Which files of a stored session a client may fetch over LCM
// (file_request_t / file_chunk_t, `adit download --products`): the session
// products (docs/PRODUCTS.md), by their path relative to the session folder.
// Nothing else of the payload's disk is reachable: no "..", no other names.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace adit::protocol {

inline constexpr std::size_t kFileChunkBytes = 48000;  // file_chunk_t stays < 60 KB
inline constexpr int kMaxChunksPerRequest = 64;        // ~3 MB answered per request
inline constexpr std::string_view kProductListPath = "products/";

// "" when `path` names a product file (products/top_view.png, grid.pgm,
// grid.yaml, occupancy.bt, occupancy.ot, targets.csv, products.json,
// sections/sections.csv, sections/section_<digits>.svg) or is
// kProductListPath; else why not.
std::string product_path_problem(std::string_view path);

// Chunks of a file of `bytes` (an empty file has one, empty).
std::int32_t file_chunk_count(std::uint64_t bytes);

}  // namespace adit::protocol
