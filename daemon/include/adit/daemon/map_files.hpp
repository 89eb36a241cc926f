#pragma once
// A session's map files (map.ply|pcd|las, session.exports), streamed tile by
// tile so that a long session's map never has to fit in RAM whole. Both a
// finished session (sessions.cpp) and a recovered one (session_recovery.cpp)
// write them here.

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "adit/protocol/map_point.hpp"
#include "adit/slam/tiled_map.hpp"

namespace adit::slam {
class LiveGrid;
}

namespace adit::daemon {

// Writes the live 2D grid as STEM.pgm and STEM.yaml (ROS map_server), over
// its patches' bounding box; returns the bytes written, 0 when the grid has
// no patch (nothing written). Throws adit::InputError naming a file that
// cannot be written.
std::uintmax_t write_live_grid(const std::filesystem::path& stem, const slam::LiveGrid& grid);

// A corner at or below every point of the tiles `coords` (tile_size_m each)
// once moved by `placed_by` (the prior map's frame, session_frame.hpp, or
// identity), lowered by `margin_m` (points moved by the loops' correction
// before that), floored to whole metres: the LAS offset.
std::array<double, 3> map_corner(const std::vector<slam::TileCoord>& coords, double tile_size_m, double margin_m,
                                 const Eigen::Isometry3d& placed_by);

// Writes dir/map.<format> for each of `formats` with `n_points` points, asking
// `read` for each tile's points in the order of `coords` (its vector is
// replaced). Returns the files' names; throws what the writers throw (a count
// that differs from `n_points`, a file that cannot be written).
std::vector<std::string> write_map_files(
    const std::filesystem::path& dir, const std::vector<std::string>& formats, std::uint64_t n_points,
    const std::array<double, 3>& corner, const std::vector<slam::TileCoord>& coords,
    const std::function<void(const slam::TileCoord&, std::vector<protocol::MapPoint>&)>& read);

}  // namespace adit::daemon
