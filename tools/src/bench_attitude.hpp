#pragma once
// adit bench attitude: how well scan-to-map registration follows the body's
// roll and pitch when everything else is given by the ground truth (each scan
// deskewed by it, its position pinned to it). A diagnostic for the
// odometry's tilt error, which is what costs the map its accuracy at range.

#include <CLI/CLI.hpp>

namespace adit::tools {

void add_bench_attitude_command(CLI::App& bench, int& status);

}  // namespace adit::tools
