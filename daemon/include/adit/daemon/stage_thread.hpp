#pragma once
// One pipeline thread: its name ("adit-<name>" for the kernel, <name> for its
// heartbeat), the thread settings it applies to itself when it starts
// (thread_settings.hpp), its CPU time for the status, and what it could not
// apply. The thread's body beats the heartbeat; `finished` is set when the
// body returns, so a thread that ended normally is not taken for stalled.

#include <pthread.h>

#include <atomic>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "adit/config/config.hpp"
#include "adit/daemon/heartbeat.hpp"

namespace adit::daemon {

class StageThread {
 public:
  StageThread(std::string name, const config::ThreadSettings& settings, const std::atomic<bool>& stop);
  ~StageThread() { join(); }
  StageThread(const StageThread&) = delete;
  StageThread& operator=(const StageThread&) = delete;

  template <typename Body>
  void start(Body&& body) {
    thread_ = std::thread([this, body = std::forward<Body>(body)]() mutable {
      settle();
      body();
      beat.finished.store(true, std::memory_order_release);
    });
    handle_.store(thread_.native_handle(), std::memory_order_relaxed);
    running_.store(true, std::memory_order_release);
  }
  void join() {
    running_.store(false, std::memory_order_release);
    if (thread_.joinable()) thread_.join();
  }

  // For Handoff's waits: beats, and goes on waiting until the pipeline stops.
  bool idle() {
    beat.beat();
    return !stop_.load(std::memory_order_relaxed);
  }
  bool stopping() const { return stop_.load(std::memory_order_relaxed); }

  const std::string& name() const { return beat.name; }
  double cpu_s() const;                    // 0 before start() and after join()
  std::vector<std::string> warnings() const;  // settings that could not be applied

  Heartbeat beat;

 private:
  void settle();  // on the thread, once: name, policy, CPU

  config::ThreadSettings settings_;
  const std::atomic<bool>& stop_;
  mutable std::mutex warnings_mutex_;  // taken once at start and by readers, never per item
  std::vector<std::string> warnings_;
  std::thread thread_;
  // thread_'s handle for its CPU clock, readable from the status thread while the thread runs.
  std::atomic<pthread_t> handle_{};
  std::atomic<bool> running_{false};
};

}  // namespace adit::daemon
