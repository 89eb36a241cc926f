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
#include "adit/daemon/allocator.hpp"
#include "adit/slam/gravity.hpp"

namespace adit::daemon {
namespace {

constexpr int kNice = 10;  // below every other stage under SCHED_OTHER

}  // namespace

// With an accelerometer the map's poses hold roll and pitch by gravity
// (decision 008; the map refiner keeps them within σ 0.002 rad of the
// odometry's): the graph keeps them too, so that a loop's vertical gap is
// closed in height, not by tilting the whole route about its start (which
// moved the middle of a 254 m loop by 0.25 m in z on mine:robot:300:5).
//
// Those ups are the accelerometer's, bias and all: its bias walks
// (imu.accel_bias_walk), and b/g rad of tilt climbs b/g of the distance
// driven (0.12 m/s² on mine:robot:300:5: 1.2 cm a metre). The graph lets the
// ups' tilt walk as much (PoseGraph::tilt_walk_rad_per_sqrt_s), so a loop
// that closes in height corrects the tilt along the route.
slam::LoopClosureConfig loop_closure_config(const config::Config& config, slam::LoopClosureConfig loops) {
  if (config.imu.enabled && loops.gravity_sigma_rad <= 0.0) loops.gravity_sigma_rad = 0.002;
  if (config.imu.enabled && loops.tilt_walk_rad_per_sqrt_s <= 0.0 && config.map.loops_tilt_walk)
    loops.tilt_walk_rad_per_sqrt_s = config.imu.accel_bias_walk / slam::kStandardGravity;
  loops.optimize_every_s = config.map.loops_optimize_every_s;
  return loops;
}

LoopClosureStage::LoopClosureStage(const config::Config& config, PipelineStats& stats, const std::atomic<bool>& stop,
                                   const slam::LoopClosureConfig& loops, bool live)
    : stats_(stats),
      live_source_(live),
      thread_("loops", config::ThreadSettings{}, stop),  // SCHED_OTHER whatever the other stages use, never FIFO
      keyframes_(live ? 0 : kMaxKeyframesBehind),
      closer_(loop_closure_config(config, loops)) {}

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
  bool catching_up = false;
  while (!thread_.stopping()) {
    thread_.beat.beat();
    std::optional<KeyframeItem> k = keyframes_.pop(std::chrono::milliseconds(200));
    if (!k) {
      if (keyframes_.closed_and_empty()) break;
      continue;
    }
    const std::size_t accepted_before = closer_.stats().accepted;
    const std::size_t file_errors_before = closer_.scans().read_errors() + closer_.scans().write_errors();
    const std::size_t waiting = keyframes_.depth();
    const bool search = !live_source_ || waiting <= kMaxKeyframesBehind;
    if (!search && !catching_up)
      log::warn("loops: {} keyframes waiting: adding them without a loop search until {} or fewer wait", waiting,
                kMaxKeyframesBehind);
    if (search && catching_up)
      log::info("loops: caught up at keyframe {} ({} keyframes so far added without a search)", closer_.stats().keyframes,
                closer_.stats().keyframes_not_searched);
    catching_up = !search;
    const bool optimised = closer_.add_keyframe(k->stamp_ns, k->pose, k->points, search, k->anchored);
    update_stats();  // before a correction is posted: a status showing it counts the loops that made it
    if (optimised) {
      const Eigen::Isometry3d c = closer_.correction();
      log::info("loops: keyframe {}: {} loop(s) accepted, graph optimised in {:.3f} s; correction {:.3f} m",
                closer_.stats().keyframes - 1, closer_.stats().accepted - accepted_before,
                closer_.stats().last_optimization_s, c.translation().norm());
      if (closer_.stats().accepted > 0) live_.post(closer_.correction_track());
      // The solve's blocks (Ceres, CHOLMOD: thousands, sized by the graph)
      // are freed, but their pages stay in this thread's arena, a high-water
      // mark that grows with the graph (allocator.hpp).
      return_free_pages();
    }
    if (closer_.scans().read_errors() + closer_.scans().write_errors() > file_errors_before)
      log::warn("loops: {}", closer_.scans().last_error());
  }
  if (thread_.stopping()) return;
  const std::int64_t t0 = monotonic_ns();
  closer_.refine();
  refine_time_s_ = 1e-9 * static_cast<double>(monotonic_ns() - t0);
  update_stats();
  // The correction the map files follow, for the live tiles' last placement
  // (MappingStage::follow_final_correction) and the status's frame.
  if (closer_.stats().accepted > 0) live_.post(closer_.correction_track());
}

void LoopClosureStage::update_stats() {
  const slam::LoopClosureStats& s = closer_.stats();
  stats_.loop_keyframes.store(s.keyframes, std::memory_order_relaxed);
  stats_.loop_candidates.store(s.candidates, std::memory_order_relaxed);
  if (s.accepted > stats_.loops_accepted.load(std::memory_order_relaxed))
    stats_.last_loop_realtime_ns.store(realtime_ns(), std::memory_order_relaxed);
  stats_.loops_accepted.store(s.accepted, std::memory_order_relaxed);
  stats_.loops_rejected.store(s.rejected_verification + s.rejected_inconsistent, std::memory_order_relaxed);
}

}  // namespace adit::daemon
