#pragma once
// adit bench prior-map: global localisation against a prior map on a
// simulated session (docs/PRIOR-MAP.md).

#include <CLI/CLI.hpp>

namespace adit::tools {

void add_bench_prior_map_command(CLI::App& bench, int& status);

}  // namespace adit::tools
