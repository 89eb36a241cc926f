#pragma once
// The schema visitor that writes the effective configuration back as YAML
// (`adit config show`). Internal to adit_config.

#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "adit/config/schema.hpp"

namespace adit::config::detail {

class YamlWriter {
 public:
  explicit YamlWriter(YAML::Emitter& out) : out_(out) {}

  template <typename T, typename... Check>
  void required(std::string_view key, T& value, const Check&... check) {
    optional(key, value, check...);
  }

  template <typename T, typename... Check>
  void optional(std::string_view key, T& value, const Check&... check) {
    out_ << YAML::Key << std::string(key) << YAML::Value;
    emit(value, check...);
  }

  template <typename S>
  void section(std::string_view key, S& sub) {
    out_ << YAML::Key << std::string(key) << YAML::Value << YAML::BeginMap;
    describe(*this, sub);
    out_ << YAML::EndMap;
  }

  template <typename S>
  void list(std::string_view key, std::vector<S>& items) {
    out_ << YAML::Key << std::string(key) << YAML::Value << YAML::BeginSeq;
    for (auto& item : items) {
      out_ << YAML::BeginMap;
      describe(*this, item);
      out_ << YAML::EndMap;
    }
    out_ << YAML::EndSeq;
  }

 private:
  template <typename T, typename... Check>
  void emit(const T& value, const Check&...) {
    out_ << value;
  }
  template <typename N, typename Check>
  void emit(const std::array<N, 3>& value, const Check&) {
    out_ << YAML::Flow << YAML::BeginSeq << value[0] << value[1] << value[2] << YAML::EndSeq;
  }
  // Shortest text that reads back to the same double (0.05, not 0.050000000000000003).
  template <typename Check>
  void emit(const double& value, const Check&) {
    out_ << fmt::format("{}", value);
  }
  void emit(const std::vector<std::string>& value, const OneOf&) {
    out_ << YAML::Flow << YAML::BeginSeq;
    for (const std::string& item : value) out_ << item;
    out_ << YAML::EndSeq;
  }
  template <typename E>
  void emit(const E& value, const Names<E>& names) {
    for (const auto& [name, v] : names.table)
      if (v == value) out_ << std::string(name);
  }

  YAML::Emitter& out_;
};

}  // namespace adit::config::detail
