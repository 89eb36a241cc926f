#pragma once
// Loading and checking a payload configuration. Every program goes through
// load_config(); every problem is an adit::InputError naming the file, the
// line and the dotted key, e.g.
//   payload.yaml:14: lidar.prot: unknown key (did you mean 'port'?)

#include <filesystem>
#include <string>
#include <string_view>

#include "adit/config/config.hpp"

namespace adit::config {

// Reads, validates and returns the configuration in `file`. Relative paths in
// it are resolved against the file's folder.
Config load_config(const std::filesystem::path& file);

// The same from YAML text; `name` stands for the file in messages and
// `base_dir` resolves relative paths.
Config parse_config(std::string_view yaml, const std::string& name,
                    const std::filesystem::path& base_dir);

// The effective configuration, every key with its value, as YAML.
std::string to_yaml(const Config& config);

}  // namespace adit::config
