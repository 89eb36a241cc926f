// The loop-closure stage. In: keyframes from the mapping thread. Out: the
// pose graph and the map→odometry correction. Thread "loops", low priority;
// never blocks another stage. (loop_closure_stage.hpp)
#include "adit/daemon/loop_closure_stage.hpp"

#include <chrono>

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include "adit/common/clock.hpp"
#include "adit/common/log.hpp"

namespace adit::daemon {
namespace {

constexpr int kNice = 10;  // below every other stage under SCHED_OTHER

config::ThreadSettings background(const config::ThreadSettings&) { return {}; }  // never SCHED_FIFO

}  // namespace

LoopClosureStage::LoopClosureStage(const config::Config& config, PipelineStats& stats, const std::atomic<bool>& stop,
                                   const slam::LoopClosureConfig& loops)
    : stats_(stats), thread_("loops", background(config.threads.mapping), stop), closer_(loops) {}

void LoopClosureStage::start() {
  thread_.start([this] { loop(); });
}

void LoopClosureStage::finish() {
  keyframes_.close();
  thread_.join();
}

void LoopClosureStage::loop() {
  // Linux: a thread's nice value is per thread (setpriority on its tid).
  if (setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), kNice) != 0)
    log::warn("loops: could not lower the thread's priority");
  while (!thread_.stopping()) {
    thread_.beat.beat();
    std::optional<KeyframeItem> k = keyframes_.pop(std::chrono::milliseconds(200));
    if (!k) {
      if (keyframes_.closed_and_empty()) break;
      continue;
    }
    const std::size_t accepted_before = closer_.stats().accepted;
    if (closer_.add_keyframe(k->stamp_ns, k->pose, k->points)) {
      const Eigen::Isometry3d c = closer_.correction();
      log::info("loops: keyframe {}: {} loop(s) accepted, graph optimised in {:.3f} s; correction {:.3f} m",
                closer_.stats().keyframes - 1, closer_.stats().accepted - accepted_before,
                closer_.stats().last_optimization_s, c.translation().norm());
    }
    update_stats();
  }
  if (thread_.stopping()) return;
  const std::int64_t t0 = monotonic_ns();
  closer_.refine();
  refine_time_s_ = 1e-9 * static_cast<double>(monotonic_ns() - t0);
  update_stats();
}

void LoopClosureStage::update_stats() {
  const slam::LoopClosureStats& s = closer_.stats();
  stats_.loop_keyframes.store(s.keyframes, std::memory_order_relaxed);
  stats_.loop_candidates.store(s.candidates, std::memory_order_relaxed);
  stats_.loops_accepted.store(s.accepted, std::memory_order_relaxed);
  stats_.loops_rejected.store(s.rejected_verification + s.rejected_inconsistent, std::memory_order_relaxed);
}

}  // namespace adit::daemon
