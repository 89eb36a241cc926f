#pragma once
// The watchdog: checks every worker's heartbeat and tells systemd the daemon
// is alive (sd_notify WATCHDOG=1) only while all of them are; a stalled worker
// stops the petting, so systemd's WatchdogSec restarts the daemon. Also sends
// READY=1 once and STATUS= lines (sd_notify(3)); without systemd
// (NOTIFY_SOCKET unset) the notifications are no-ops.

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>

#include "adit/daemon/heartbeat.hpp"

namespace adit::daemon {

struct SupervisorVerdict {
  bool healthy = true;
  std::string stalled;  // names of stalled workers, comma separated
};

// Pure: which workers have not beaten within `stall_ns` at `now_ns`.
SupervisorVerdict check_heartbeats(std::span<const Heartbeat* const> beats, std::int64_t now_ns, std::int64_t stall_ns);

// The watchdog interval systemd asked for (WATCHDOG_USEC), if any.
std::optional<std::int64_t> systemd_watchdog_ns();

// sd_notify wrappers; return false when not under systemd or on error.
bool notify_ready(const std::string& status);
bool notify_status(const std::string& status);
bool notify_watchdog();
bool notify_stopping();

}  // namespace adit::daemon
