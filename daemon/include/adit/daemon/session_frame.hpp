#pragma once
// The frame a session's exports are written in (docs/PRIOR-MAP.md, "The
// session's frame"): the prior map's once the odometry anchored to it, else
// gravity's level when the odometry measured gravity (an IMU's or the
// accelerometer's up: the odometry frame turned about its origin so that z
// is plumb, decision 060), else the odometry's own. The anchor,
// prior_from_odometry, is kept in the session's prior_frame.json the moment
// it is found; the level, level_from_odometry, in level_frame.json by the
// mapping thread as the odometry's up settles. At the session's end, and on
// a recovery after a crash, the map files and the trajectories are written
// through it, and summary.json's "frame" says which frame they are in.
// The tiles/ folder stays in the odometry frame; the live tiles too, unless
// map.loops_move_map moves them by the loop closure's graph (the live
// frame_t places them either way; docs/LOOPS.md "Live tiles"). Then, at the
// session's end, tiles_graph/ holds them as the graph placed them last, with
// that last correction, and a download after a restart is served from it.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "adit/daemon/map_frame.hpp"
#include "adit/slam/correction_track.hpp"

namespace adit::daemon {

// A finished session's tiles placed by the pose graph's last correction, and
// that correction (graph_from_odometry), when loop closure moved its map.
constexpr const char* kGraphTilesFolder = "tiles_graph";
constexpr const char* kGraphTilesPartialFolder = "tiles_graph.partial";  // being written
constexpr const char* kGraphCorrectionFile = "correction.json";

// Writes the anchor durably (a 4 × 4 matrix, row by row); throws
// std::runtime_error naming the file when it cannot be written.
void write_prior_frame(const std::filesystem::path& file, const Eigen::Isometry3d& prior_from_odometry);

// The anchor in `file`, nullopt when the file does not exist. A file that is
// not a finite rigid 4 × 4 matrix throws adit::InputError naming it and the key.
std::optional<Eigen::Isometry3d> read_prior_frame(const std::filesystem::path& file);
// The same from the file's text; `name` is the file named in errors.
Eigen::Isometry3d parse_prior_frame(std::string_view text, const std::string& name);

// Gravity's level (slam::level_from_up of the odometry's up), as
// write_prior_frame and read_prior_frame keep the anchor.
void write_level_frame(const std::filesystem::path& file, const Eigen::Isometry3d& level_from_odometry);
std::optional<Eigen::Isometry3d> read_level_frame(const std::filesystem::path& file);

// Rewrites the TUM trajectory `file` with each pose T at time t as
// A·C(t)·T, durably, under a first line saying which: A is `frame`'s
// (the prior's anchor or gravity's level), C is `track`'s correction (the
// pose graph's, as the map files are moved); each identity when absent. A
// file already under such a line is left as it is (a recovery after a crash
// between this and the summary does not move it twice). Returns false when
// there is no such file; throws adit::InputError naming a malformed one,
// std::runtime_error one that cannot be written.
bool place_trajectory_file(const std::filesystem::path& file, const ExportFrame& frame,
                           const slam::CorrectionTrack* track = nullptr);

// A finished session's two trajectories in `dir` placed as its map files:
// map_trajectory.tum (the poses the map was built at, M) by `track`'s C(t),
// trajectory.tum (the odometry's, P, which the map's refinement moved to M)
// by slam::retargeted: each pose to A·C(t)·M(t), where the graph put the
// map's pose. Without `track` (or when map_trajectory.tum is placed already
// or missing) both as place_trajectory_file does.
void place_session_trajectories(const std::filesystem::path& dir, const ExportFrame& frame,
                                const slam::CorrectionTrack* track);

// The graph's last correction C (graph <- odometry), written durably into
// tiles_graph/; read back as read_prior_frame reads the anchor.
void write_graph_correction(const std::filesystem::path& file, const Eigen::Isometry3d& graph_from_odometry);
std::optional<Eigen::Isometry3d> read_graph_correction(const std::filesystem::path& file);

// The frame of the finished session in `dir` as frame_t gives it: its anchor
// (prior_frame.json) and, when tiles_graph/ is there, the graph's last
// correction; nullopt in the odometry's own frame. Throws adit::InputError
// naming a malformed file.
std::optional<MapFrame> stored_session_frame(const std::filesystem::path& dir);

// summary.json's "frame": {"name": "prior_map", "prior_from_odometry": 4 × 4}
// with an anchor, {"name": "level", "level_from_odometry": 4 × 4, "tilt_deg"}
// levelled (tilt_deg: how far the odometry frame's z was from plumb),
// {"name": "odometry"} else.
nlohmann::json frame_summary(const ExportFrame& frame);

}  // namespace adit::daemon
