#pragma once
// The schema visitor that reads YAML into the configuration structs and
// rejects anything the schema does not describe. Internal to adit_config.

#include <charconv>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "adit/common/error.hpp"
#include "adit/config/schema.hpp"

namespace adit::config::detail {

struct ReadContext {
  std::string file;
  std::map<std::string, int, std::less<>> lines;  // dotted key -> 1-based line of its value
};

// The closest of `candidates` to `word` by edit distance, if it is close enough
// to be a plausible typo; empty otherwise.
std::string closest_key(std::string_view word, const std::vector<std::string>& candidates);

class YamlReader {
 public:
  // `node` may be undefined/null (an absent section): required keys then fail
  // at `missing_line`, the line of the nearest enclosing mapping.
  YamlReader(YAML::Node node, std::string prefix, ReadContext& ctx, int missing_line);

  template <typename T, typename... Check>
  void required(std::string_view key, T& value, const Check&... check) {
    read(key, value, true, check...);
  }
  template <typename T, typename... Check>
  void optional(std::string_view key, T& value, const Check&... check) {
    read(key, value, false, check...);
  }

  template <typename S>
  void section(std::string_view key, S& sub) {
    const YAML::Node child = child_of(key);
    const std::string path = join(key);
    const int line = child ? line_of(child) : own_line();
    if (child && !child.IsNull() && !child.IsMap()) fail(line, path, "expected a mapping of keys");
    YamlReader reader(child, path, ctx_, line);
    describe(reader, sub);
    reader.finish();
  }

  template <typename S>
  void list(std::string_view key, std::vector<S>& items) {
    const YAML::Node child = child_of(key);
    if (!child || child.IsNull()) return;
    const std::string path = join(key);
    if (!child.IsSequence()) fail(line_of(child), path, "expected a list");
    items.clear();
    for (std::size_t i = 0; i < child.size(); ++i) {
      const YAML::Node element = child[i];
      const std::string element_path = fmt::format("{}[{}]", path, i);
      if (!element.IsMap()) fail(line_of(element), element_path, "expected a mapping of keys");
      YamlReader reader(element, element_path, ctx_, line_of(element));
      describe(reader, items.emplace_back());
      reader.finish();
    }
  }

  // Rejects keys the schema did not ask for, and keys given twice.
  void finish() const;

  [[noreturn]] void fail(int line, const std::string& key, const std::string& reason) const;

 private:
  YAML::Node child_of(std::string_view key);
  std::string join(std::string_view key) const;
  int own_line() const;
  static int line_of(const YAML::Node& node) { return node.Mark().line + 1; }

  template <typename T, typename... Check>
  void read(std::string_view key, T& value, bool is_required, const Check&... check) {
    const YAML::Node child = child_of(key);
    const std::string path = join(key);
    if (!child || child.IsNull()) {
      if (is_required) fail(own_line(), path, "required key is missing");
      return;
    }
    const int line = line_of(child);
    ctx_.lines[path] = line;
    convert(child, value, line, path, check...);
  }

  std::string scalar(const YAML::Node& node, int line, const std::string& path, std::string_view what) const;

  void convert(const YAML::Node& node, std::string& out, int line, const std::string& path) const;
  void convert(const YAML::Node& node, std::string& out, int line, const std::string& path, const OneOf& one_of) const;
  void convert(const YAML::Node& node, bool& out, int line, const std::string& path) const;

  template <typename N>
    requires std::is_arithmetic_v<N>
  void convert(const YAML::Node& node, N& out, int line, const std::string& path, const Range<N>& range) const {
    out = number<N>(node, line, path);
    if (!(out >= range.lo && out <= range.hi))
      fail(line, path, fmt::format("expected a value in [{}, {}], got {}", range.lo, range.hi, scalar(node, line, path, "")));
  }
  template <typename N>
    requires std::is_arithmetic_v<N>
  void convert(const YAML::Node& node, N& out, int line, const std::string& path) const {
    out = number<N>(node, line, path);
  }

  template <typename N>
  void convert(const YAML::Node& node, std::array<N, 3>& out, int line, const std::string& path,
               const Range<N>& range) const {
    if (!node.IsSequence() || node.size() != 3) fail(line, path, "expected a list of 3 numbers");
    for (std::size_t i = 0; i < 3; ++i) convert(node[i], out[i], line, path, range);
  }

  // A list of names, each one of `one_of`, none twice.
  void convert(const YAML::Node& node, std::vector<std::string>& out, int line, const std::string& path,
               const OneOf& one_of) const;

  template <typename E>
  void convert(const YAML::Node& node, E& out, int line, const std::string& path, const Names<E>& names) const {
    const std::string text = scalar(node, line, path, "a name");
    std::string allowed;
    for (const auto& [name, value] : names.table) {
      if (name == text) {
        out = value;
        return;
      }
      allowed += fmt::format("{}{}", allowed.empty() ? "" : ", ", name);
    }
    fail(line, path, fmt::format("expected one of: {}; got '{}'", allowed, text));
  }

  template <typename N>
  N number(const YAML::Node& node, int line, const std::string& path) const {
    const std::string text = scalar(node, line, path, "a number");
    N value{};
    if constexpr (std::is_floating_point_v<N>) {
      const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
      if (ec != std::errc{} || end != text.data() + text.size() || !std::isfinite(value))
        fail(line, path, fmt::format("expected a number, got '{}'", text));
    } else {
      // Decimal, or hexadecimal with 0x (CAN identifiers are usually written so).
      const bool hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
      const char* begin = text.data() + (hex ? 2 : 0);
      const auto [end, ec] = std::from_chars(begin, text.data() + text.size(), value, hex ? 16 : 10);
      if (ec == std::errc::result_out_of_range) fail(line, path, fmt::format("integer out of range: '{}'", text));
      if (ec != std::errc{} || end != text.data() + text.size())
        fail(line, path, fmt::format("expected an integer, got '{}'", text));
    }
    return value;
  }

  YAML::Node node_;
  std::string prefix_;
  ReadContext& ctx_;
  int missing_line_;
  std::vector<std::string> known_;
};

}  // namespace adit::config::detail
