#pragma once
// The pipeline's output stage: poses in, poses out of the pipeline.
//
// In:   every scan's odometry result (PoseSlot), in scan order.
// Out:  the pose sink (PipelineSinks::pose: LCM on aditd), the session's
//       trajectory file (TUM, valid poses), the pose counts and each scan's
//       latency from its last packet to its pose.
// Thread "output": no allocation or lock per pose; the sink must be quick and
// must not throw; the trajectory is buffered stdio, handed to the kernel
// once a second (a crash loses at most that much of it).

#include <atomic>
#include <filesystem>

#include "adit/config/config.hpp"
#include "adit/daemon/handoff.hpp"
#include "adit/daemon/pipeline_items.hpp"
#include "adit/daemon/pipeline_stats.hpp"
#include "adit/daemon/stage_thread.hpp"
#include "adit/slam/tum.hpp"

namespace adit::daemon {

class OutputStage {
 public:
  OutputStage(const config::Config& config, Handoff<PoseSlot>& poses, PipelineSinks::PoseSink sink,
              PipelineStats& stats, PipelineTimings& timings, const std::atomic<bool>& stop);

  // The trajectory (TUM) goes to `file` (throws adit::InputError naming it). Before start().
  void write_trajectory_to(const std::filesystem::path& file);
  void start();
  void join() { thread_.join(); }

  StageThread& thread() { return thread_; }
  const Handoff<PoseSlot>& input() const { return poses_; }

 private:
  void loop();

  Handoff<PoseSlot>& poses_;
  PipelineSinks::PoseSink sink_;
  PipelineStats& stats_;
  PipelineTimings& timings_;
  StageThread thread_;
  slam::TumWriter trajectory_;
  std::int64_t last_flush_ns_ = 0;  // of trajectory_, monotonic
};

}  // namespace adit::daemon
