#pragma once
// A prepared prior map on disk (`adit prior-map prepare` writes it, aditd and
// the benchmarks read it): DIR/prior_map.bin, little-endian: the magic
// "ADIT-PRIOR-MAP 1\n", then the point spacing, the points and their
// normals, the plan grid (origin, cell, size, likelihood, floor heights, wall
// distances) and the normal counts. Reading checks every size against the
// file's length and throws adit::InputError naming the file on anything wrong.

#include <filesystem>

#include "adit/slam/prior_map.hpp"

namespace adit::slam {

inline constexpr const char* kPriorMapFile = "prior_map.bin";

void write_prior_map(const std::filesystem::path& dir, const PriorMap& prior);
// `path`: the folder holding prior_map.bin, or the file itself.
PriorMap read_prior_map(const std::filesystem::path& path);

}  // namespace adit::slam
