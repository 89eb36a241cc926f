#include "adit/daemon/stage_thread.hpp"

#include <time.h>

#include "adit/daemon/thread_settings.hpp"

namespace adit::daemon {

StageThread::StageThread(std::string name, const config::ThreadSettings& settings, const std::atomic<bool>& stop)
    : beat(std::move(name)), settings_(settings), stop_(stop) {}

void StageThread::settle() {
  std::vector<std::string> w = apply_thread_settings("adit-" + beat.name, settings_);
  const std::lock_guard lock(warnings_mutex_);
  warnings_ = std::move(w);
}

double StageThread::cpu_s() const {
  clockid_t clock{};
  timespec t{};
  if (!running_.load(std::memory_order_acquire) ||
      pthread_getcpuclockid(handle_.load(std::memory_order_relaxed), &clock) != 0 ||
      clock_gettime(clock, &t) != 0)
    return 0.0;
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

std::vector<std::string> StageThread::warnings() const {
  const std::lock_guard lock(warnings_mutex_);
  return warnings_;
}

}  // namespace adit::daemon
