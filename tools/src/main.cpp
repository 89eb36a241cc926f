// adit: the command-line client and tools (the tablet's reference).

#include <CLI/CLI.hpp>

#include "adit/common/log.hpp"
#include "adit/common/main.hpp"
#include "commands.hpp"

int main(int argc, char** argv) {
  return adit::guarded_main("adit", [&]() -> int {
    CLI::App app{"adit: command-line client and tools for the adit LiDAR mapping daemon"};
    app.require_subcommand(1);
    app.set_help_all_flag("--help-all", "Print help for every subcommand and exit");
    app.fallthrough();  // global options may follow the subcommand
    adit::log::init("adit", adit::log::Level::info);
    app.add_option_function<std::string>(
           "--log-level", [](const std::string& name) { adit::log::set_level(*adit::log::parse_level(name)); },
           "Log level: trace, debug, info, warn, error, off (default info)")
        ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
    int status = adit::kExitOk;
    adit::tools::register_config_commands(app, status);
    adit::tools::register_bench_commands(app, status);
    adit::tools::register_lidar_commands(app, status);
    adit::tools::register_eval_commands(app, status);
    adit::tools::register_can_commands(app, status);
    adit::tools::register_calibrate_wheels_commands(app, status);
    adit::tools::register_calibrate_mounting_commands(app, status);
    adit::tools::register_client_commands(app, status);
    adit::tools::register_keygen_commands(app, status);
    adit::tools::register_faults_commands(app, status);
    adit::tools::register_download_commands(app, status);
    adit::tools::register_console_commands(app, status);
    adit::tools::register_sim_commands(app, status);
    adit::tools::register_replay_commands(app, status);
    adit::tools::register_products_commands(app, status);
    adit::tools::register_targets_commands(app, status);
    adit::tools::register_georef_commands(app, status);
    adit::tools::register_prior_map_commands(app, status);
    adit::tools::register_join_commands(app, status);
    try {
      app.parse(argc, argv);
    } catch (const CLI::Success& e) {
      return app.exit(e);
    } catch (const CLI::ParseError& e) {
      app.exit(e);
      return adit::kExitBadInput;
    }
    return status;
  });
}
