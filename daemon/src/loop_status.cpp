// The loop closure's progress for the live status (loop_status.hpp).
#include "adit/daemon/loop_status.hpp"

#include <algorithm>
#include <climits>
#include <cmath>

#include <Eigen/Geometry>

namespace adit::daemon {

LoopStatus loop_status_of(const PipelineStats& stats, const slam::CorrectionTrack* correction, bool moves_map) {
  const auto count = [](const std::atomic<std::uint64_t>& n) {
    return static_cast<std::int32_t>(std::min<std::uint64_t>(n.load(std::memory_order_relaxed), INT32_MAX));
  };
  LoopStatus out;
  out.keyframes = count(stats.loop_keyframes);
  out.candidates = count(stats.loop_candidates);
  out.accepted = count(stats.loops_accepted);
  out.rejected = count(stats.loops_rejected);
  out.last_loop_utime = stats.last_loop_realtime_ns.load(std::memory_order_relaxed) / 1000;
  out.moves_map = moves_map;
  if (correction != nullptr && !correction->empty()) {
    const Eigen::Isometry3d& c = correction->corrections().back();
    out.correction_m = static_cast<float>(c.translation().norm());
    out.correction_deg = static_cast<float>(Eigen::AngleAxisd(c.rotation()).angle() * 180.0 / M_PI);
  }
  return out;
}

}  // namespace adit::daemon
