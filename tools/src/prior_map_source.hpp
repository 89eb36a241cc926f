#pragma once
// A prior map for the `adit prior-map` commands and the benchmark: a prepared
// folder (or its prior_map.bin) is read as it is; any other file (cloud or
// mesh) is read and prepared on the spot, with the same steps as `prepare`.

#include <filesystem>
#include <string>

#include "adit/protocol/prior_input.hpp"
#include "adit/slam/prior_map.hpp"

namespace adit::tools {

struct LoadedPrior {
  slam::PriorMap map;
  bool prepared_now = false;   // read from a source file and prepared in this run
  double prepare_s = 0.0;      // time that took (read and prepare)
  std::size_t input_points = 0;
};

// Throws adit::InputError naming the file when it cannot be read, or when the
// prepared map fails check_prior_map (wrong units or axes, no walls, no floor).
LoadedPrior load_prior(const std::filesystem::path& path, const protocol::PriorInputOptions& options = {});

// The prepared map's memory (points, normals, plan), bytes.
std::size_t prior_map_bytes(const slam::PriorMap& prior);

}  // namespace adit::tools
