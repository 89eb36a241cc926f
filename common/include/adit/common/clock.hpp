#pragma once
// The clocks of the project, one helper each.
//   monotonic: durations, latencies, heartbeats, pacing (never steps);
//   realtime:  wall time for people and files (LCM's `utime` is realtime_us()).

#include <chrono>
#include <cstdint>

namespace adit {

inline std::int64_t monotonic_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Nanoseconds since the Unix epoch.
inline std::int64_t realtime_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Microseconds since the Unix epoch: the time every LCM message starts with.
inline std::int64_t realtime_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace adit
