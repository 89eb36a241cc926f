#pragma once
// A small file (summary.json) written so that a crash leaves either the old
// file or the whole new one, never half of it: written beside, flushed to the
// disk (fsync), renamed into place, and the folder's entry synced.

#include <filesystem>
#include <string_view>

namespace adit::daemon {

// Throws std::runtime_error naming the file when it cannot be written.
void write_durably(const std::filesystem::path& file, std::string_view text);

}  // namespace adit::daemon
