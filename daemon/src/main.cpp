// aditd: the real-time LiDAR mapping daemon.

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "adit/common/log.hpp"
#include "adit/common/main.hpp"
#include "adit/config/load.hpp"
#include "adit/daemon/run.hpp"

namespace {
constexpr const char* kDefaultConfig = "/etc/adit/aditd.yaml";
}

int main(int argc, char** argv) {
  return adit::guarded_main("aditd", [&]() -> int {
    CLI::App app{
        "aditd: real-time LiDAR mapping daemon.\n"
        "Reads LiDAR packets, wheel encoders and GPIO as configured, runs odometry and mapping,\n"
        "and serves poses, status and map tiles to the tablet over LCM.\n"
        "Exit status: 0 ok, 1 runtime failure, 2 bad option or configuration."};
    std::string config_file = kDefaultConfig;
    bool check_only = false;
    bool print_config = false;
    std::string log_level;
    adit::daemon::RunOptions run_options;
    app.add_option("-c,--config", config_file, "Payload configuration (YAML), see firmware-config/")
        ->capture_default_str();
    app.add_flag("-t,--check-config", check_only,
                 "Validate the configuration and exit: 0 when valid, 2 with a message naming file, line and key");
    app.add_flag("--print-config", print_config,
                 "Print the effective configuration (every key, defaults filled in) and exit");
    app.add_option("--log-level", log_level, "Override log.level: trace, debug, info, warn, error, off")
        ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
    app.add_flag("--once", run_options.once,
                 "Start a session at once and exit when it ends (the recording runs out, STOP, or a signal); "
                 "its files are in <state_dir>/sessions/<id>/");
    app.set_version_flag("--version", "aditd 0.1.0");
    try {
      app.parse(argc, argv);
    } catch (const CLI::Success& e) {
      return app.exit(e);
    } catch (const CLI::ParseError& e) {
      app.exit(e);
      return adit::kExitBadInput;
    }

    const adit::config::Config config = adit::config::load_config(config_file);
    if (check_only) {
      fmt::print("aditd: configuration {} is valid\n", config_file);
      return adit::kExitOk;
    }
    if (print_config) {
      fmt::print("{}", adit::config::to_yaml(config));
      return adit::kExitOk;
    }
    const auto level = log_level.empty() ? config.log.level : *adit::log::parse_level(log_level);
    adit::log::init("aditd", level);
    return adit::daemon::run(config, config_file, run_options);
  });
}
