#pragma once
// Rebuilding an interrupted session from its journal (journal_writer.hpp;
// docs/SESSIONS.md). A session folder with a journal.adj and no summary.json
// was cut short: aditd crashed, was killed, or lost power. Its journal is
// read up to its last good record (a torn tail is cut off the file and
// reported: how many bytes, and how much later the odometry's trajectory
// went); the map's tiles (tiles/<id>.adt), the map files, map_trajectory.tum
// and keyframes.tum are rewritten from it; summary.json says "recovered".
// Then the journal is removed, as after a clean stop.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "adit/daemon/session_frame.hpp"

namespace adit::daemon {

struct RecoveryReport {
  std::string session;
  bool recovered = false;
  std::string problem;           // why not, when !recovered
  std::uint64_t journal_bytes = 0;
  std::uint64_t cut_bytes = 0;   // the torn tail cut off
  std::string cut_reason;        // "" when the journal ended on a whole record
  bool ended_cleanly = false;    // the journal has its end record (the crash came while writing the files)
  std::uint64_t records = 0;
  std::uint64_t unreadable_records = 0;  // checked but not decodable: skipped
  std::uint64_t map_poses = 0;
  std::uint64_t keyframes = 0;
  std::uint64_t points = 0;
  std::uint64_t tiles = 0;
  double first_stamp_s = 0.0;    // of the journal's map poses
  double last_stamp_s = 0.0;
  // How far the odometry's trajectory.tum went past the journal's last map
  // pose: the part of the session the map lost (0 when it did not).
  double lost_s = 0.0;
  // The frame the exports are in (session_frame.hpp): the prior's
  // (prior_frame.json), else gravity's level (level_frame.json, written when
  // the session was ending), else the odometry's; a file that could not be
  // read is logged and left out.
  ExportFrame frame;
  std::vector<std::string> files;
};

// Sessions under `sessions_root` that were cut short, oldest first.
std::vector<std::filesystem::path> interrupted_sessions(const std::filesystem::path& sessions_root);

// Rebuilds one (writes `exports`: map.<format> for each); never throws: what
// went wrong is in the report. `tile_size_m` is used when the journal's
// header cannot be read.
RecoveryReport recover_session(const std::filesystem::path& dir, const std::vector<std::string>& exports,
                               double tile_size_m);

// One line for the log and the status: what was recovered and what was lost.
std::string describe(const RecoveryReport& report);

}  // namespace adit::daemon
