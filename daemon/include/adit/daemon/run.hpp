#pragma once
// The daemon's entry point after the configuration is loaded.

#include <filesystem>

#include "adit/config/config.hpp"

namespace adit::daemon {

struct RunOptions {
  // Start a session at launch and exit once it has ended (its recording ran
  // out, a STOP came, or a signal): replays from scripts and tests.
  bool once = false;
};

// Runs aditd with `config` until it is told to stop; returns the exit status.
int run(const config::Config& config, const std::filesystem::path& config_file, const RunOptions& options = {});

}  // namespace adit::daemon
