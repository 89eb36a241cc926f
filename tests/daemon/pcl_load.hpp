#pragma once
// Loads a map file with PCL, as an operator's tools would; kept in its own
// translation unit so PCL's headers compile once.

#include <filesystem>
#include <optional>
#include <string>

namespace adit::test {

// True when the tests were built with PCL.
bool have_pcl();
// The number of points PCL reads from a PLY or PCD file, or nullopt with `error` set.
std::optional<std::size_t> pcl_point_count(const std::filesystem::path& file, std::string& error);

}  // namespace adit::test
