#pragma once
// adit bench loops: loop closure's cost against the odometry's (docs/LOOPS.md).

#include <CLI/CLI.hpp>

namespace adit::tools {

void add_bench_loops_command(CLI::App& bench, int& status);

}  // namespace adit::tools
