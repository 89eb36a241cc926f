#pragma once
// The clocks of the project, one helper each.
//   monotonic: durations, latencies, heartbeats, pacing (never steps);
//   realtime:  wall time for people and files (LCM's `utime` is realtime_us());
//   thread CPU: what the calling thread spent, whatever else the machine runs (benchmarks, products).

#include <chrono>
#include <cstdint>

#include <time.h>

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

// CPU time of the calling thread (CLOCK_THREAD_CPUTIME_ID), nanoseconds.
inline std::int64_t thread_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace adit
