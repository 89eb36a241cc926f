#include "adit/daemon/supervisor.hpp"

#include <systemd/sd-daemon.h>

namespace adit::daemon {

SupervisorVerdict check_heartbeats(std::span<const Heartbeat* const> beats, std::int64_t now_ns, std::int64_t stall_ns) {
  SupervisorVerdict verdict;
  for (const Heartbeat* beat : beats) {
    if (beat->finished.load(std::memory_order_relaxed) || beat->age_ns(now_ns) <= stall_ns) continue;
    verdict.healthy = false;
    verdict.stalled += (verdict.stalled.empty() ? "" : ", ") + beat->name;
  }
  return verdict;
}

std::optional<std::int64_t> systemd_watchdog_ns() {
  std::uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) > 0) return static_cast<std::int64_t>(usec) * 1000;
  return std::nullopt;
}

bool notify_ready(const std::string& status) { return sd_notify(0, ("READY=1\nSTATUS=" + status).c_str()) > 0; }
bool notify_status(const std::string& status) { return sd_notify(0, ("STATUS=" + status).c_str()) > 0; }
bool notify_watchdog() { return sd_notify(0, "WATCHDOG=1") > 0; }
bool notify_stopping() { return sd_notify(0, "STOPPING=1") > 0; }

}  // namespace adit::daemon
