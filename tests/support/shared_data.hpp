#pragma once
// Locating ../shared/data for realdata tests, and this build's source and
// build trees. ADIT_SHARED_DATA in the environment wins; otherwise the folder
// beside the source tree. The paths are defined in the file CMake generates
// from test_paths.cpp.in.

#include <cstdlib>
#include <filesystem>
#include <optional>

#include <gtest/gtest.h>

namespace adit::test {

std::filesystem::path source_dir();
std::filesystem::path binary_dir();
std::filesystem::path shared_data_default();  // ../shared/data beside the source tree

inline std::optional<std::filesystem::path> shared_data_dir() {
  const char* env = std::getenv("ADIT_SHARED_DATA");
  const std::filesystem::path dir = env != nullptr ? env : shared_data_default();
  if (std::filesystem::is_directory(dir)) return std::filesystem::canonical(dir);
  return std::nullopt;
}

}  // namespace adit::test

// Skips the current test, with a message naming what is missing, unless
// `relative` exists under the shared data folder; otherwise binds `var` to it.
#define ADIT_REQUIRE_SHARED_DATA(var, relative)                                          \
  const auto var##_root = ::adit::test::shared_data_dir();                               \
  if (!var##_root || !std::filesystem::exists(*var##_root / (relative)))                 \
    GTEST_SKIP() << "shared data not found: " << (relative)                              \
                 << " (looked in ADIT_SHARED_DATA or ../shared/data beside the project)"; \
  const std::filesystem::path var = *var##_root / (relative)
