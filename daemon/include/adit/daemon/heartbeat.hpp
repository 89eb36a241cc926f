#pragma once
// A worker's sign of life: the worker bumps it every loop (one relaxed atomic
// store, fine for a hot path), the supervisor reads it. A worker that waits
// for input also beats, so "stalled" means stuck, not idle.

#include <atomic>
#include <cstdint>
#include <string>

#include "adit/common/clock.hpp"

namespace adit::daemon {

struct Heartbeat {
  explicit Heartbeat(std::string thread_name) : name(std::move(thread_name)) {}
  void beat() { last_ns.store(monotonic_ns(), std::memory_order_relaxed); }
  std::int64_t age_ns(std::int64_t now_ns) const { return now_ns - last_ns.load(std::memory_order_relaxed); }

  std::string name;
  std::atomic<std::int64_t> last_ns{monotonic_ns()};
  std::atomic<bool> finished{false};  // a worker that ended normally is not stalled
};

}  // namespace adit::daemon
