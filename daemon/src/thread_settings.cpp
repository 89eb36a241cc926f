#include "adit/daemon/thread_settings.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

namespace adit::daemon {

std::vector<std::string> apply_thread_settings(std::string_view name, const config::ThreadSettings& settings) {
  std::vector<std::string> warnings;
  const std::string short_name(name.substr(0, 15));  // the kernel's limit (TASK_COMM_LEN - 1)
  pthread_setname_np(pthread_self(), short_name.c_str());

  if (settings.policy == config::SchedPolicy::fifo) {
    sched_param param{};
    param.sched_priority = settings.priority;
    if (const int err = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param); err != 0) {
      warnings.push_back(fmt::format(
          "thread {}: SCHED_FIFO priority {} refused ({}); running with normal scheduling "
          "(grant CAP_SYS_NICE or LimitRTPRIO in the systemd unit)",
          short_name, settings.priority, std::strerror(err)));
    }
  }
  if (settings.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(static_cast<unsigned>(settings.cpu), &set);
    if (const int err = pthread_setaffinity_np(pthread_self(), sizeof(set), &set); err != 0) {
      warnings.push_back(fmt::format("thread {}: pinning to CPU {} refused ({}); running on any CPU", short_name,
                                     settings.cpu, std::strerror(err)));
    }
  }
  return warnings;
}

std::vector<std::string> lock_memory() {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) return {};
  return {fmt::format("mlockall refused ({}); memory may be paged out under pressure "
                      "(set LimitMEMLOCK=infinity in the systemd unit)",
                      std::strerror(errno))};
}

}  // namespace adit::daemon
