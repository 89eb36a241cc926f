#pragma once
// The session's path as the pose graph places it, for a client that draws
// the map moved by the loops (graph_path_t, docs/PROTOCOL.md): the graph's
// keyframe positions, thinned evenly to what one message holds.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "adit/slam/correction_track.hpp"

namespace adit::daemon {

// One message's worth: 4000 positions of 12 bytes, under the protocol's 60 KB.
constexpr std::size_t kGraphPathMaxPoints = 4000;

struct GraphPath {
  std::int64_t utime = 0;        // µs: the newest keyframe's stamp (pose_t's clock)
  std::int32_t n_keyframes = 0;  // before thinning
  std::vector<std::array<float, 3>> positions;  // oldest first, in the graph's (the tiles') frame
};

// Every keyframe of `track` when there are at most `max_points` (≥ 2), else
// `max_points` of them evenly spaced in index, the first and the newest kept.
GraphPath graph_path_of(const slam::CorrectionTrack& track, std::size_t max_points = kGraphPathMaxPoints);

}  // namespace adit::daemon
