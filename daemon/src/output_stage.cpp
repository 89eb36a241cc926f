// The output stage. In: every scan's pose. Out: the pose sink, the
// trajectory file, pose counts and latencies. Thread output; no allocation
// or lock per pose. (output_stage.hpp)
#include "adit/daemon/output_stage.hpp"

#include "adit/common/clock.hpp"

namespace adit::daemon {

OutputStage::OutputStage(const config::Config& config, Handoff<PoseSlot>& poses, PipelineSinks::PoseSink sink,
                         PipelineStats& stats, PipelineTimings& timings, const std::atomic<bool>& stop)
    : poses_(poses), sink_(std::move(sink)), stats_(stats), timings_(timings), thread_("output", config.threads.publisher, stop) {
  timings_.latency_ms.reserve(kTimingCapacity);
}

void OutputStage::write_trajectory_to(const std::filesystem::path& file) {
  if (!file.empty()) trajectory_ = slam::TumWriter(file);
}

void OutputStage::start() {
  thread_.start([this] { loop(); });
}

void OutputStage::loop() {
  while (!thread_.stopping()) {
    PoseSlot* slot = poses_.take_or_wait([this] { return thread_.idle(); });
    if (slot == nullptr) break;
    thread_.beat.beat();
    const slam::OdometryResult& r = slot->result;
    stats_.poses.fetch_add(1, std::memory_order_relaxed);
    if (!r.valid) stats_.invalid_poses.fetch_add(1, std::memory_order_relaxed);
    if (r.status == slam::OdometryStatus::degenerate) stats_.degenerate_poses.fetch_add(1, std::memory_order_relaxed);
    if (r.status == slam::OdometryStatus::lost) stats_.lost_poses.fetch_add(1, std::memory_order_relaxed);
    if (r.status == slam::OdometryStatus::relocalised) stats_.relocalised_poses.fetch_add(1, std::memory_order_relaxed);
    if (r.search_cut) stats_.searches_cut.fetch_add(1, std::memory_order_relaxed);
    if (timings_.latency_ms.size() < kTimingCapacity)
      timings_.latency_ms.push_back(1e-6 * static_cast<double>(slot->pose_mono_ns - slot->last_packet_mono_ns));
    if (sink_) sink_(r);
    if (r.valid) trajectory_.write(r.stamp_ns, r.pose);
    poses_.release(slot);
    // Once a second to the kernel (one write of ~10 lines): a crash then
    // loses at most a second of the trajectory, not a whole stdio buffer.
    if (const std::int64_t now = monotonic_ns(); now - last_flush_ns_ >= 1'000'000'000) {
      trajectory_.flush();
      last_flush_ns_ = now;
    }
  }
  trajectory_.flush();
}

}  // namespace adit::daemon
