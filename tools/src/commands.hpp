#pragma once
// Each `adit` subcommand lives in its own cmd_*.cpp and registers itself on the
// top-level CLI11 app through one of these functions (called from main.cpp).
// A registration adds the subcommand and its options and sets a callback that
// stores the exit status in `status`; errors are thrown as adit::InputError.

#include <CLI/CLI.hpp>

namespace adit::tools {

void register_config_commands(CLI::App& app, int& status);
void register_bench_commands(CLI::App& app, int& status);

void register_lidar_commands(CLI::App& app, int& status);
void register_eval_commands(CLI::App& app, int& status);
void register_can_commands(CLI::App& app, int& status);
void register_calibrate_wheels_commands(CLI::App& app, int& status);
void register_calibrate_mounting_commands(CLI::App& app, int& status);

// status, watch, start, stop, export, sessions, ping (the tablet protocol)
void register_client_commands(CLI::App& app, int& status);
// keygen: a key file for signed commands
void register_keygen_commands(CLI::App& app, int& status);
void register_faults_commands(CLI::App& app, int& status);

void register_download_commands(CLI::App& app, int& status);
// console: the web app for tablets and phones (cmd_console.cpp)
void register_console_commands(CLI::App& app, int& status);
void register_sim_commands(CLI::App& app, int& status);
void register_replay_commands(CLI::App& app, int& status);
void register_products_commands(CLI::App& app, int& status);
void register_targets_commands(CLI::App& app, int& status);
// georef: a session in site coordinates from total-station control points
void register_georef_commands(CLI::App& app, int& status);
void register_prior_map_commands(CLI::App& app, int& status);
// join: a session placed into a stored session's map (cmd_join.cpp)
void register_join_commands(CLI::App& app, int& status);

}  // namespace adit::tools
