#include "adit/common/error.hpp"

namespace adit {
namespace {
std::string compose(const std::string& where, const std::string& key, const std::string& what) {
  std::string line = where;
  if (!key.empty()) line += (line.empty() ? "" : ": ") + key;
  return line + (line.empty() ? "" : ": ") + what;
}
}  // namespace

InputError::InputError(std::string where, std::string key, std::string what)
    : std::runtime_error(compose(where, key, what)),
      where_(std::move(where)),
      key_(std::move(key)),
      reason_(std::move(what)) {}

}  // namespace adit
