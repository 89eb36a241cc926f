// The frame a session's exports are in (session_frame.hpp).
#include "adit/daemon/session_frame.hpp"

#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/daemon/durable_file.hpp"
#include "adit/slam/levelling.hpp"
#include "adit/slam/tum.hpp"

namespace adit::daemon {
namespace {

constexpr const char* kKey = "prior_from_odometry";
constexpr const char* kCorrectionKey = "graph_from_odometry";
constexpr const char* kLevelKey = "level_from_odometry";
// The first line of a trajectory file moved into the map's frame (any such line: placed).
constexpr std::string_view kPlacedPrefix = "# frame: ";
constexpr std::string_view kPlacedLine = "# frame: prior_map (prior_from_odometry of prior_frame.json applied)";
constexpr std::string_view kCorrectedLine = "# frame: loops (the pose graph's correction applied, as to the map files)";
constexpr std::string_view kPlacedCorrectedLine =
    "# frame: prior_map (the pose graph's correction and prior_from_odometry of prior_frame.json applied)";
constexpr std::string_view kLevelLine = "# frame: level (level_from_odometry of level_frame.json applied: z is plumb)";
constexpr std::string_view kLevelCorrectedLine =
    "# frame: level (the pose graph's correction and level_from_odometry of level_frame.json applied: z is plumb)";

// The first line of a trajectory placed by `source`, moved by the graph or not.
std::string_view placed_line(ExportSource source, bool corrected) {
  switch (source) {
    case ExportSource::prior_map: return corrected ? kPlacedCorrectedLine : kPlacedLine;
    case ExportSource::level: return corrected ? kLevelCorrectedLine : kLevelLine;
    case ExportSource::odometry: break;
  }
  return kCorrectedLine;
}

nlohmann::json rows_of(const Eigen::Isometry3d& t) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (int c = 0; c < 4; ++c) row.push_back(t.matrix()(r, c));
    rows.push_back(row);
  }
  return rows;
}

// The whole of `file`; nullopt when it does not exist, adit::InputError when
// it exists and cannot be read.
std::optional<std::string> read_text(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) {
    if (!std::filesystem::exists(file)) return std::nullopt;
    throw InputError(file.string(), "", "cannot be read");
  }
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A rigid 4 × 4 matrix under `key` of the JSON `text`, as rows_of writes it;
// `what` names the kind of file in errors.
Eigen::Isometry3d parse_transform(std::string_view text, const std::string& name, const char* key, const char* what) {
  const nlohmann::json j = nlohmann::json::parse(text.begin(), text.end(), nullptr, false);
  if (!j.is_object() || !j.contains(key)) throw InputError(name, key, fmt::format("missing (not {})", what));
  const nlohmann::json& rows = j.at(key);
  if (!rows.is_array() || rows.size() != 4) throw InputError(name, key, "not a 4 x 4 matrix");
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    const nlohmann::json& row = rows[static_cast<std::size_t>(r)];
    if (!row.is_array() || row.size() != 4) throw InputError(name, key, "not a 4 x 4 matrix");
    for (int c = 0; c < 4; ++c) {
      const nlohmann::json& v = row[static_cast<std::size_t>(c)];
      if (!v.is_number() || !std::isfinite(v.get<double>())) throw InputError(name, key, "not finite numbers");
      m(r, c) = v.get<double>();
    }
  }
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  const bool rigid = (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() < 1e-6 && r.determinant() > 0.0 &&
                     m.row(3) == Eigen::RowVector4d(0, 0, 0, 1);
  if (!rigid) throw InputError(name, key, "not a rigid transform (rotation and translation)");
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(r).normalized().toRotationMatrix();
  t.translation() = m.topRightCorner<3, 1>();
  return t;
}

// `t` under `key`, with a note for whoever opens the file, written durably.
void write_transform(const std::filesystem::path& file, const char* key, const Eigen::Isometry3d& t, const char* note) {
  const nlohmann::json j = {{key, rows_of(t)}, {"note", note}};
  write_durably(file, j.dump(2) + "\n");
}

// parse_transform of `file`; nullopt when it does not exist.
std::optional<Eigen::Isometry3d> read_transform(const std::filesystem::path& file, const char* key, const char* what) {
  const std::optional<std::string> text = read_text(file);
  if (!text) return std::nullopt;
  return parse_transform(*text, file.string(), key, what);
}

}  // namespace

void write_prior_frame(const std::filesystem::path& file, const Eigen::Isometry3d& prior_from_odometry) {
  write_transform(file, kKey, prior_from_odometry,
                  "the session's live poses and tiles are in the odometry frame; this places them in the prior "
                  "map's, where its exports are (summary.json \"frame\")");
}

Eigen::Isometry3d parse_prior_frame(std::string_view text, const std::string& name) {
  return parse_transform(text, name, kKey, "a prior frame file");
}

std::optional<Eigen::Isometry3d> read_prior_frame(const std::filesystem::path& file) {
  return read_transform(file, kKey, "a prior frame file");
}

void write_graph_correction(const std::filesystem::path& file, const Eigen::Isometry3d& graph_from_odometry) {
  write_transform(file, kCorrectionKey, graph_from_odometry,
                  "the pose graph's last correction: the tiles in this folder are in the graph's frame, the "
                  "session's trajectory.tum in the odometry's; this places the latter in the former");
}

std::optional<Eigen::Isometry3d> read_graph_correction(const std::filesystem::path& file) {
  return read_transform(file, kCorrectionKey, "a graph correction file");
}

void write_level_frame(const std::filesystem::path& file, const Eigen::Isometry3d& level_from_odometry) {
  write_transform(file, kLevelKey, level_from_odometry,
                  "gravity's level as the odometry measured it: this turns the odometry frame (the first scan's "
                  "body frame) about its origin so that z is plumb; the session's exports are in the turned frame "
                  "(summary.json \"frame\"), its tiles/ and live poses in the odometry's");
}

std::optional<Eigen::Isometry3d> read_level_frame(const std::filesystem::path& file) {
  return read_transform(file, kLevelKey, "a level frame file");
}

ExportFrame export_frame(const std::optional<Eigen::Isometry3d>& anchor, const std::optional<Eigen::Isometry3d>& level) {
  if (anchor) return {ExportSource::prior_map, *anchor};
  if (level) return {ExportSource::level, *level};
  return {};
}

std::optional<MapFrame> map_frame_of(const ExportFrame& base, const std::optional<Eigen::Isometry3d>& correction,
                                     const Eigen::Isometry3d& refinement) {
  const bool refined = !refinement.isApprox(Eigen::Isometry3d::Identity(), 1e-12);
  if (base.source == ExportSource::odometry && !correction && !refined) return std::nullopt;
  const Eigen::Isometry3d& tiles = base.from_odometry;
  const Eigen::Isometry3d odometry = (correction ? tiles * *correction : tiles) * refinement;
  const auto put = [](const Eigen::Isometry3d& t, std::array<double, 3>& p, std::array<double, 4>& q) {
    const Eigen::Quaterniond r(t.linear());
    p = {t.translation().x(), t.translation().y(), t.translation().z()};
    q = {r.w(), r.x(), r.y(), r.z()};
  };
  MapFrame f;
  f.source = base.source == ExportSource::prior_map ? kFrameSourcePriorMap
             : base.source == ExportSource::level   ? kFrameSourceLevel
             : correction                           ? kFrameSourceLoops
                                                    : kFrameSourceOdometry;
  put(odometry, f.position, f.orientation);
  put(tiles, f.tiles_position, f.tiles_orientation);
  return f;
}

std::optional<MapFrame> stored_session_frame(const std::filesystem::path& dir) {
  const std::optional<Eigen::Isometry3d> anchor = read_prior_frame(dir / "prior_frame.json");
  const std::optional<Eigen::Isometry3d> level = anchor ? std::nullopt : read_level_frame(dir / "level_frame.json");
  const std::optional<Eigen::Isometry3d> correction =
      std::filesystem::is_directory(dir / kGraphTilesFolder)
          ? read_graph_correction(dir / kGraphTilesFolder / kGraphCorrectionFile)
          : std::nullopt;
  return map_frame_of(export_frame(anchor, level), correction);
}

namespace {

// `file`'s poses while it is not placed yet (a first line kPlacedPrefix
// says it is: nullopt); throws as place_trajectory_file says. `file` exists.
std::optional<slam::Trajectory> read_unplaced(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), "", "cannot be read");
  std::string first;
  std::getline(in, first);
  if (first.starts_with(kPlacedPrefix)) return std::nullopt;
  in.clear();
  in.seekg(0);
  return slam::read_tum(in, file);
}

// `t`, read from `file`, rewritten there as place_trajectory_file says
// (`track` null or not empty).
void write_placed(const std::filesystem::path& file, const ExportFrame& frame, const slam::CorrectionTrack* track,
                  slam::Trajectory t) {
  const Eigen::Isometry3d& a = frame.from_odometry;
  for (std::size_t i = 0; i < t.poses.size(); ++i) {
    const auto stamp_ns = static_cast<std::int64_t>(std::llround(t.stamps[i] * 1e9));
    t.poses[i] = track != nullptr ? a * track->at(stamp_ns) * t.poses[i] : a * t.poses[i];
  }
  std::ostringstream out;
  out << placed_line(frame.source, track != nullptr) << "\n# timestamp tx ty tz qx qy qz qw\n";
  slam::write_tum(out, t);
  write_durably(file, out.str());
}

}  // namespace

bool place_trajectory_file(const std::filesystem::path& file, const ExportFrame& frame,
                           const slam::CorrectionTrack* track) {
  if (!std::filesystem::exists(file)) return false;
  if (track != nullptr && track->empty()) track = nullptr;
  if (frame.source == ExportSource::odometry && track == nullptr) return true;  // nothing to move
  if (std::optional<slam::Trajectory> t = read_unplaced(file)) write_placed(file, frame, track, std::move(*t));
  return true;
}

void place_session_trajectories(const std::filesystem::path& dir, const ExportFrame& frame,
                                const slam::CorrectionTrack* track) {
  const std::filesystem::path map_poses = dir / "map_trajectory.tum";
  const std::filesystem::path odometry = dir / "trajectory.tum";
  // The odometry's first: its track is made from the map's poses as they
  // were built, before they are placed.
  std::optional<slam::Trajectory> built_at;
  if (track != nullptr && !track->empty() && std::filesystem::exists(map_poses)) built_at = read_unplaced(map_poses);
  if (!built_at) {
    place_trajectory_file(odometry, frame, track);
    place_trajectory_file(map_poses, frame, track);
    return;
  }
  if (std::filesystem::exists(odometry))
    if (std::optional<slam::Trajectory> poses = read_unplaced(odometry)) {
      const slam::CorrectionTrack moved = slam::retargeted(*track, *built_at, *poses);
      write_placed(odometry, frame, moved.empty() ? nullptr : &moved, std::move(*poses));
    }
  write_placed(map_poses, frame, track, std::move(*built_at));
}

nlohmann::json frame_summary(const ExportFrame& frame) {
  switch (frame.source) {
    case ExportSource::prior_map: return {{"name", "prior_map"}, {kKey, rows_of(frame.from_odometry)}};
    case ExportSource::level:
      return {{"name", "level"},
              {kLevelKey, rows_of(frame.from_odometry)},
              {"tilt_deg", slam::tilt_of(frame.from_odometry) * 180.0 / M_PI}};
    case ExportSource::odometry: break;
  }
  return {{"name", "odometry"}};
}

}  // namespace adit::daemon
