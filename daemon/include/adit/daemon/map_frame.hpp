#pragma once
// Where a session's odometry frame and its tiles lie in its map frame: what
// frame_t carries (docs/PROTOCOL.md). The map frame is the prior map's once
// the odometry anchored to it (A: prior_from_odometry), else gravity's level
// when the odometry measured gravity (A: level_from_odometry, decision 060),
// else the odometry's own; the tiles are in the odometry frame, or in the
// pose graph's when the loop closure moves the map (map.loops_move_map),
// which the graph's latest correction C places: map <- tiles = A,
// map <- odometry = A·C·D (docs/LOOPS.md, "Live tiles"). D is the map's
// refinement of the odometry at the latest scan mapped (M·O⁻¹: the tiles are
// built at the refined poses M, the poses published are the odometry's O;
// slam::MapRefiner), so a pose lands where its scan went into the tiles.

#include <array>
#include <cstdint>
#include <optional>

#include <Eigen/Geometry>

namespace adit::daemon {

constexpr std::int8_t kFrameSourceOdometry = 0;  // frame_t.SOURCE_*
constexpr std::int8_t kFrameSourcePriorMap = 1;
constexpr std::int8_t kFrameSourceLoops = 2;
constexpr std::int8_t kFrameSourceLevel = 3;

struct MapFrame {
  std::int8_t source = kFrameSourceOdometry;  // frame_t.SOURCE_*
  std::array<double, 3> position{};               // map <- odometry (the poses)
  std::array<double, 4> orientation{1, 0, 0, 0};  // w, x, y, z
  std::array<double, 3> tiles_position{};         // map <- tiles
  std::array<double, 4> tiles_orientation{1, 0, 0, 0};
};

// Where the exports go from the odometry frame (or the pose graph's).
enum class ExportSource { odometry, prior_map, level };
struct ExportFrame {
  ExportSource source = ExportSource::odometry;
  Eigen::Isometry3d from_odometry = Eigen::Isometry3d::Identity();  // map <- odometry
};
// The prior's `anchor` when there is one, else the `level`, else the odometry's own.
ExportFrame export_frame(const std::optional<Eigen::Isometry3d>& anchor, const std::optional<Eigen::Isometry3d>& level);

// The frame of a session placed by `base` (A: the prior's anchor or
// gravity's level), whose tiles the graph's `correction` (C, the latest)
// moved and whose poses the map's `refinement` (D) places among its tiles;
// nullopt when it has none of them (the odometry's own frame).
std::optional<MapFrame> map_frame_of(const ExportFrame& base, const std::optional<Eigen::Isometry3d>& correction,
                                     const Eigen::Isometry3d& refinement = Eigen::Isometry3d::Identity());

}  // namespace adit::daemon
