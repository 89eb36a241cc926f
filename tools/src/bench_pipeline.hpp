#pragma once
// adit bench pipeline: latency of aditd's pipeline fed over UDP loopback.

#include <CLI/CLI.hpp>

namespace adit::tools {

void add_bench_pipeline_command(CLI::App& bench, int& status);

}  // namespace adit::tools
