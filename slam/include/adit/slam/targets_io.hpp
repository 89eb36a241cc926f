#pragma once
// Target lists as CSV with the header "id,x,y,z" (metres), one target per
// line. Malformed lines and duplicate ids throw adit::InputError("file:line").

#include <filesystem>
#include <vector>

#include "adit/slam/targets.hpp"

namespace adit::slam {

std::vector<Target> read_targets_csv(const std::filesystem::path& path);

}  // namespace adit::slam
