#pragma once
// Where a session's odometry frame and its tiles lie in its map frame: what
// frame_t carries (docs/PROTOCOL.md). The map frame is the prior map's once
// the odometry anchored to it (A: prior_from_odometry), else the odometry's
// own; the tiles are in the odometry frame, or in the pose graph's when the
// loop closure moves the map (map.loops_move_map), which the graph's latest
// correction C places: map <- tiles = A, map <- odometry = A·C
// (docs/LOOPS.md, "Live tiles").

#include <array>
#include <cstdint>
#include <optional>

#include <Eigen/Geometry>

namespace adit::daemon {

constexpr std::int8_t kFrameSourceOdometry = 0;  // frame_t.SOURCE_*
constexpr std::int8_t kFrameSourcePriorMap = 1;
constexpr std::int8_t kFrameSourceLoops = 2;

struct MapFrame {
  std::int8_t source = kFrameSourceOdometry;  // frame_t.SOURCE_*
  std::array<double, 3> position{};               // map <- odometry (the poses)
  std::array<double, 4> orientation{1, 0, 0, 0};  // w, x, y, z
  std::array<double, 3> tiles_position{};         // map <- tiles
  std::array<double, 4> tiles_orientation{1, 0, 0, 0};
};

// The frame of a session anchored by `anchor` (A) and whose tiles the graph's
// `correction` (C, the latest) moved; nullopt when it has neither (the
// odometry's own frame).
std::optional<MapFrame> map_frame_of(const std::optional<Eigen::Isometry3d>& anchor,
                                     const std::optional<Eigen::Isometry3d>& correction);

}  // namespace adit::daemon
