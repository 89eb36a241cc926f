#pragma once
// The daemon's entry point after the configuration is loaded.

#include <filesystem>

#include "adit/config/config.hpp"

namespace adit::daemon {

// Runs aditd with `config` until it is told to stop; returns the exit status.
int run(const config::Config& config, const std::filesystem::path& config_file);

}  // namespace adit::daemon
