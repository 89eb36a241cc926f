#pragma once
// Target lists as CSV with the header "id,x,y,z" (metres), one target per
// line, or "id,x,y,z,sigma_m" as `adit targets find` writes them (sigma not
// kept). Malformed lines and duplicate ids throw adit::InputError("file:line").

#include <filesystem>
#include <iosfwd>
#include <vector>

#include "adit/eval/targets.hpp"

namespace adit::eval {

std::vector<Target> read_targets_csv(const std::filesystem::path& path);
// The same from a stream; `name` is the file named in errors.
std::vector<Target> read_targets_csv(std::istream& in, const std::filesystem::path& name);

}  // namespace adit::eval
