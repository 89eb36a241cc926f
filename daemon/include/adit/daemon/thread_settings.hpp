#pragma once
// Naming, scheduling and pinning of the daemon's worker threads, and locking
// the process's memory, from the configuration's `threads:` section. Nothing
// here is fatal: a payload without CAP_SYS_NICE or a memlock limit still maps,
// just with less real-time margin, so each refusal comes back as a warning.

#include <string>
#include <string_view>
#include <vector>

#include "adit/config/config.hpp"

namespace adit::daemon {

// Applies name (≤ 15 characters), policy/priority and CPU to the calling
// thread; returns what could not be applied, one line each.
std::vector<std::string> apply_thread_settings(std::string_view name, const config::ThreadSettings& settings);

// mlockall(MCL_CURRENT | MCL_FUTURE); returns a warning when refused.
std::vector<std::string> lock_memory();

}  // namespace adit::daemon
