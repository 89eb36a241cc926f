#include "yaml_reader.hpp"

#include <algorithm>
#include <numeric>

namespace adit::config::detail {

namespace {
// Levenshtein distance, two rows (Wagner & Fischer 1974).
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> previous(b.size() + 1);
  std::vector<std::size_t> current(b.size() + 1);
  std::iota(previous.begin(), previous.end(), 0);
  for (std::size_t i = 1; i <= a.size(); ++i) {
    current[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t substitution = previous[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, substitution});
    }
    std::swap(previous, current);
  }
  return previous[b.size()];
}
}  // namespace

std::string closest_key(std::string_view word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_distance = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const auto& candidate : candidates) {
    const std::size_t d = edit_distance(word, candidate);
    if (d < best_distance) {
      best_distance = d;
      best = candidate;
    }
  }
  return best;
}

YamlReader::YamlReader(YAML::Node node, std::string prefix, ReadContext& ctx, int missing_line)
    : node_(std::move(node)), prefix_(std::move(prefix)), ctx_(ctx), missing_line_(missing_line) {}

YAML::Node YamlReader::child_of(std::string_view key) {
  known_.emplace_back(key);
  if (!node_ || !node_.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
  for (const auto& entry : node_) {
    if (entry.first.IsScalar() && entry.first.Scalar() == key) return entry.second;
  }
  return YAML::Node(YAML::NodeType::Undefined);
}

std::string YamlReader::join(std::string_view key) const {
  return prefix_.empty() ? std::string(key) : fmt::format("{}.{}", prefix_, key);
}

int YamlReader::own_line() const { return missing_line_; }

void YamlReader::finish() const {
  if (!node_ || !node_.IsMap()) return;
  std::vector<std::string> seen;
  for (const auto& entry : node_) {
    const int line = line_of(entry.first);
    if (!entry.first.IsScalar()) fail(line, prefix_, "keys must be plain names");
    const std::string& key = entry.first.Scalar();
    if (std::find(seen.begin(), seen.end(), key) != seen.end()) fail(line, join(key), "key is given twice");
    seen.push_back(key);
    if (std::find(known_.begin(), known_.end(), key) == known_.end()) {
      const std::string suggestion = closest_key(key, known_);
      fail(line, join(key),
           suggestion.empty() ? std::string("unknown key")
                              : fmt::format("unknown key (did you mean '{}'?)", suggestion));
    }
  }
}

void YamlReader::fail(int line, const std::string& key, const std::string& reason) const {
  throw InputError(fmt::format("{}:{}", ctx_.file, line), key, reason);
}

std::string YamlReader::scalar(const YAML::Node& node, int line, const std::string& path,
                               std::string_view what) const {
  if (!node.IsScalar()) fail(line, path, fmt::format("expected {}, got a {}", what.empty() ? "a value" : what,
                                                     node.IsMap() ? "mapping" : "list"));
  return node.Scalar();
}

void YamlReader::convert(const YAML::Node& node, std::string& out, int line, const std::string& path) const {
  out = scalar(node, line, path, "a string");
}

void YamlReader::convert(const YAML::Node& node, std::string& out, int line, const std::string& path,
                         const OneOf& one_of) const {
  out = scalar(node, line, path, "a string");
  if (std::find(one_of.allowed.begin(), one_of.allowed.end(), out) != one_of.allowed.end()) return;
  std::string allowed;
  for (const auto& name : one_of.allowed)
    if (!name.empty()) allowed += fmt::format("{}{}", allowed.empty() ? "" : ", ", name);
  fail(line, path, fmt::format("expected one of: {}; got '{}'", allowed, out));
}

void YamlReader::convert(const YAML::Node& node, std::vector<std::string>& out, int line, const std::string& path,
                         const OneOf& one_of) const {
  if (!node.IsSequence()) fail(line, path, "expected a list, e.g. [ply, las]");
  out.clear();
  for (std::size_t i = 0; i < node.size(); ++i) {
    const std::string element_path = fmt::format("{}[{}]", path, i);
    std::string name;
    convert(node[i], name, line_of(node[i]), element_path, one_of);
    if (std::find(out.begin(), out.end(), name) != out.end())
      fail(line_of(node[i]), element_path, fmt::format("'{}' is listed twice", name));
    out.push_back(std::move(name));
  }
}

void YamlReader::convert(const YAML::Node& node, bool& out, int line, const std::string& path) const {
  // YAML 1.2 core schema booleans only: yes/no/on/off are strings there, and
  // accepting them silently is how "norway problems" start.
  const std::string text = scalar(node, line, path, "true or false");
  if (text == "true" || text == "True" || text == "TRUE") {
    out = true;
  } else if (text == "false" || text == "False" || text == "FALSE") {
    out = false;
  } else {
    fail(line, path, fmt::format("expected true or false, got '{}'", text));
  }
}

}  // namespace adit::config::detail
