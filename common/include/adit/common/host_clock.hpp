#pragma once
// The host timeline live sensor data is stamped on: CLOCK_MONOTONIC moved onto
// UTC once, when the clock is made (a session's start), so stamps read as
// wall-clock time but never jump when NTP or PTP steps the wall clock. A scan
// stamped 2 s after the one before it would have the odometry predict 2 s of
// motion; one stamped 2 s before it would be dropped. CLOCK_MONOTONIC follows
// NTP's frequency slewing but not its steps (clock_gettime(2)), so neither
// does this timeline.
//
// Kernel receive stamps (SO_TIMESTAMPNS, SO_TIMESTAMP) are CLOCK_REALTIME:
// from_recent_realtime() keeps their age (how long the datagram or frame
// waited in the socket) and takes it from now, so a step between the kernel's
// stamp and the read costs nothing either: an age outside [0, kMaxAge] (a step
// in between) counts as 0.
//
// ClockStepWatch finds the steps themselves (wall clock − monotonic changing
// by more than kStep between two looks) so that they are counted and shown.

#include <cstdint>
#include <optional>

#include "adit/common/clock.hpp"

namespace adit {

class HostClock {
 public:
  static constexpr std::int64_t kMaxAge_ns = 1'000'000'000;

  HostClock() : HostClock(realtime_ns() - monotonic_ns()) {}
  explicit HostClock(std::int64_t utc_minus_monotonic_ns) : offset_ns_(utc_minus_monotonic_ns) {}

  std::int64_t now_ns() const { return monotonic_ns() + offset_ns_; }

  // A CLOCK_REALTIME stamp taken moments ago, read against both clocks now.
  static std::int64_t from_recent_realtime(std::int64_t stamp_ns, std::int64_t realtime_now_ns, std::int64_t host_now_ns) {
    const std::int64_t age = realtime_now_ns - stamp_ns;
    return host_now_ns - (age >= 0 && age <= kMaxAge_ns ? age : 0);
  }
  std::int64_t from_recent_realtime(std::int64_t stamp_ns) const {
    return from_recent_realtime(stamp_ns, realtime_ns(), now_ns());
  }

 private:
  std::int64_t offset_ns_;
};

class ClockStepWatch {
 public:
  static constexpr std::int64_t kStep_ns = 100'000'000;  // slewing moves it ≤ 0.5 ms/s (ntpd's limit)

  // The step since the last look (wall clock minus monotonic changed by more
  // than kStep_ns), signed: + the wall clock jumped ahead.
  std::optional<std::int64_t> look(std::int64_t realtime_now_ns, std::int64_t monotonic_now_ns) {
    const std::int64_t offset = realtime_now_ns - monotonic_now_ns;
    const bool first = !seen_;
    seen_ = true;
    const std::int64_t step = offset - offset_ns_;
    offset_ns_ = offset;
    if (first || (step < kStep_ns && step > -kStep_ns)) return std::nullopt;
    return step;
  }
  std::optional<std::int64_t> look() { return look(realtime_ns(), monotonic_ns()); }

 private:
  bool seen_ = false;
  std::int64_t offset_ns_ = 0;
};

}  // namespace adit
