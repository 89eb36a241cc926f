// adit config check|show: validate payload configurations, print them whole.

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/config/load.hpp"
#include "commands.hpp"

namespace adit::tools {

void register_config_commands(CLI::App& app, int& status) {
  CLI::App* config = app.add_subcommand("config", "Check and print payload configurations");
  config->require_subcommand(1);

  auto files = std::make_shared<std::vector<std::string>>();
  CLI::App* check = config->add_subcommand(
      "check", "Validate configuration files; exit 2 with file, line and key on the first error");
  check->add_option("files", *files, "Configuration files (YAML)")->required();
  check->callback([files, &status] {
    for (const auto& file : *files) {
      config::load_config(file);
      fmt::print("{}: valid\n", file);
    }
    status = kExitOk;
  });

  auto file = std::make_shared<std::string>();
  CLI::App* show = config->add_subcommand(
      "show", "Print the effective configuration: every key, with the defaults filled in");
  show->add_option("file", *file, "Configuration file (YAML)")->required();
  show->callback([file, &status] {
    fmt::print("{}", config::to_yaml(config::load_config(*file)));
    status = kExitOk;
  });
}

}  // namespace adit::tools
