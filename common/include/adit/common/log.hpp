#pragma once
// The logging facade. One logger per process, plain lines on stderr.
//
// Under systemd (JOURNAL_STREAM is set) each line starts with the sd-daemon
// priority prefix "<N>" and carries no timestamp, because journald adds its
// own and parses the prefix into PRIORITY=. On a terminal each line carries a
// timestamp and the level. Formatting happens in spdlog, but callers only see
// these functions, so the backend can change without touching the rest.
//
// Never call these from a hot path (per packet, per point, per scan in the
// odometry thread): count there, and log the counters from a slow thread.

#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>

namespace adit::log {

enum class Level { trace, debug, info, warn, error, off };

// Parses "trace|debug|info|warn|error|off"; nullopt for anything else.
std::optional<Level> parse_level(std::string_view name);
std::string_view level_name(Level level);

// Sets up the process logger. `program` names the lines; call once from main.
void init(std::string_view program, Level level);
void set_level(Level level);
Level level();

void write(Level level, std::string_view message);

template <typename... Args>
void trace(fmt::format_string<Args...> f, Args&&... args) {
  if (level() <= Level::trace) write(Level::trace, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void debug(fmt::format_string<Args...> f, Args&&... args) {
  if (level() <= Level::debug) write(Level::debug, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void info(fmt::format_string<Args...> f, Args&&... args) {
  if (level() <= Level::info) write(Level::info, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void warn(fmt::format_string<Args...> f, Args&&... args) {
  if (level() <= Level::warn) write(Level::warn, fmt::format(f, std::forward<Args>(args)...));
}
template <typename... Args>
void error(fmt::format_string<Args...> f, Args&&... args) {
  if (level() <= Level::error) write(Level::error, fmt::format(f, std::forward<Args>(args)...));
}

}  // namespace adit::log
