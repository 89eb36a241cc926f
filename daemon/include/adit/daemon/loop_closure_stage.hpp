#pragma once
// The loop-closure stage: the mapping thread's keyframes in, the pose graph
// and the map→odometry correction out (docs/LOOPS.md).
//
// In:   keyframes (KeyframeQueue), each with the pose the map placed it at.
// Out:  the graph's poses and the correction through time (correction()),
//       counts in PipelineStats (loop_*), read after join(); live, the
//       correction after each optimisation that accepted a loop (live()).
// Thread "loops", lowered to nice 10 on top of its thread settings: it takes
// the CPU the other stages leave. The odometry never sees it; the mapping
// thread only pushes into the queue. At the end it drains the queue and, with
// `refine_at_end`, optimises the whole graph once more before the exports.
// Behind a live source it never blocks another stage: with more than
// kMaxKeyframesBehind keyframes waiting, keyframes join the graph without a
// loop search (LoopCloser::add_keyframe's `search`) until the queue is short
// again, so the queue and the loops' delay stay bounded on a core too slow for
// the graph. A replay searches every keyframe, so that it gives the same graph
// on any machine, and its mapping thread waits while kMaxKeyframesBehind
// keyframes wait (KeyframeQueue's capacity), so the queue's scans stay bounded.

#include <atomic>
#include <filesystem>
#include <mutex>
#include <vector>

#include "adit/config/config.hpp"
#include "adit/daemon/correction_board.hpp"
#include "adit/daemon/keyframe_queue.hpp"
#include "adit/daemon/pipeline_stats.hpp"
#include "adit/daemon/stage_thread.hpp"
#include "adit/slam/correction_track.hpp"
#include "adit/slam/loop_closer.hpp"

namespace adit::daemon {

inline constexpr std::size_t kMaxKeyframesBehind = 10;  // about 10 s of a walk, 2 s of a fast drone

// The loop closer's settings for `config`: `loops` with, given an IMU, the
// gravity priors and the tilt walk (the stage's; `adit bench loops` uses it too).
slam::LoopClosureConfig loop_closure_config(const config::Config& config, slam::LoopClosureConfig loops = {});

class LoopClosureStage {
 public:
  // `live`: the keyframes come from a live source (see above).
  LoopClosureStage(const config::Config& config, PipelineStats& stats, const std::atomic<bool>& stop,
                   const slam::LoopClosureConfig& loops = {}, bool live = false);

  KeyframeQueue& input() { return keyframes_; }
  // Before start(): keyframe scans beyond the closer's window go to `folder`.
  void spill_to(const std::filesystem::path& folder) { closer_.spill_scans_to(folder); }
  void start();
  // After the mapping stage has joined: closes the queue, lets the thread
  // drain it and refine, and joins.
  void finish();

  StageThread& thread() { return thread_; }
  // Complete after finish().
  const slam::LoopCloser& closer() const { return closer_; }
  slam::CorrectionTrack correction() const { return closer_.correction_track(); }
  // While it runs: the correction after the latest optimisation that accepted a loop.
  const CorrectionBoard& live() const { return live_; }
  double refine_time_s() const { return refine_time_s_; }

 private:
  void loop();
  void update_stats();

  PipelineStats& stats_;
  const bool live_source_;
  StageThread thread_;
  KeyframeQueue keyframes_;
  slam::LoopCloser closer_;
  CorrectionBoard live_;
  double refine_time_s_ = 0.0;
};

}  // namespace adit::daemon
