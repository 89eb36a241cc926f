#include "adit/protocol/product_files.hpp"

#include <algorithm>
#include <array>
#include <cctype>

#include <fmt/format.h>

namespace adit::protocol {

std::string product_path_problem(std::string_view path) {
  if (path == kProductListPath) return "";
  constexpr std::array<std::string_view, 8> kFiles{
      "products/top_view.png", "products/grid.pgm",     "products/grid.yaml",    "products/occupancy.bt",
      "products/occupancy.ot", "products/targets.csv",  "products/products.json", "products/sections/sections.csv"};
  if (std::find(kFiles.begin(), kFiles.end(), path) != kFiles.end()) return "";
  constexpr std::string_view kSection = "products/sections/section_";
  if (path.size() > kSection.size() + 4 && path.substr(0, kSection.size()) == kSection &&
      path.substr(path.size() - 4) == ".svg") {
    const std::string_view digits = path.substr(kSection.size(), path.size() - kSection.size() - 4);
    if (digits.size() <= 6 &&
        std::all_of(digits.begin(), digits.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }))
      return "";
  }
  return fmt::format("'{}' is not a product file (products/top_view.png, grid.pgm, grid.yaml, occupancy.bt, ...)",
                     path.substr(0, 120));
}

std::int32_t file_chunk_count(std::uint64_t bytes) {
  return bytes == 0 ? 1 : static_cast<std::int32_t>((bytes + kFileChunkBytes - 1) / kFileChunkBytes);
}

}  // namespace adit::protocol
