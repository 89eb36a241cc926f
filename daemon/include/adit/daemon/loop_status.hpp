#pragma once
// The loop closure's progress for the live status (loop_status_t, sent with
// each status_t while a session's loop closure runs; docs/LOOPS.md): its
// counts, when the newest loop was accepted, and how far the graph's
// correction moves the odometry at its newest keyframe.

#include <cstdint>

#include "adit/daemon/pipeline_stats.hpp"
#include "adit/slam/correction_track.hpp"

namespace adit::daemon {

struct LoopStatus {
  std::int32_t keyframes = 0;
  std::int32_t candidates = 0;
  std::int32_t accepted = 0;
  std::int32_t rejected = 0;
  std::int64_t last_loop_utime = 0;  // µs, wall clock; 0: no loop yet
  float correction_m = 0.0F;         // the correction at the graph's newest keyframe
  float correction_deg = 0.0F;
  bool moves_map = false;            // map.loops_move_map
};

// From the loop-closure thread's counts and its latest correction (null
// before the first loop: none).
LoopStatus loop_status_of(const PipelineStats& stats, const slam::CorrectionTrack* correction, bool moves_map);

}  // namespace adit::daemon
