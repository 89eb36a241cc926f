#include "adit/eval/targets_io.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <string>
#include <unordered_set>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "text_fields.hpp"

namespace adit::eval {

std::vector<Target> read_targets_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), "", "cannot open for reading");
  return read_targets_csv(in, path);
}

std::vector<Target> read_targets_csv(std::istream& in, const std::filesystem::path& path) {
  std::vector<Target> targets;
  std::unordered_set<std::string> seen;
  std::vector<std::string_view> fields;
  std::string line;
  bool header = false;
  std::size_t columns = 4;  // 5 with sigma_m (`adit targets find`), not read
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    if (detail::is_comment_or_blank(line)) continue;
    const std::string where = fmt::format("{}:{}", path.string(), number);
    detail::split_fields(line, ",", fields);
    if (!header) {
      std::string joined;
      for (const auto f : fields) joined += std::string(f) + ",";
      std::transform(joined.begin(), joined.end(), joined.begin(), [](unsigned char c) { return std::tolower(c); });
      if (joined == "id,x,y,z,sigma_m,") {
        columns = 5;
      } else if (joined != "id,x,y,z,") {
        throw InputError(where, "header", fmt::format("expected 'id,x,y,z' or 'id,x,y,z,sigma_m', found '{}'", line));
      }
      header = true;
      continue;
    }
    if (fields.size() != columns)
      throw InputError(where, "", fmt::format("expected {} fields, found {}", columns, fields.size()));
    if (fields[0].empty()) throw InputError(where, "id", "is empty");
    Target t{std::string(fields[0]), {}};
    for (int k = 0; k < 3; ++k) {
      const auto v = detail::parse_double(fields[static_cast<std::size_t>(k + 1)]);
      if (!v)
        throw InputError(where, std::string(1, "xyz"[k]),
                         fmt::format("'{}' is not a finite number", fields[static_cast<std::size_t>(k + 1)]));
      t.position(k) = *v;
    }
    if (!seen.insert(t.id).second) throw InputError(where, "id", fmt::format("'{}' appears twice", t.id));
    targets.push_back(std::move(t));
  }
  if (!header) throw InputError(path.string(), "header", "missing: expected 'id,x,y,z'");
  return targets;
}

}  // namespace adit::eval
