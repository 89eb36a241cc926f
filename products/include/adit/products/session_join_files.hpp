#pragma once
// Joining two stored sessions' folders (issue #20, part 5; docs/LOOPS.md,
// Joining sessions): the stored session's map.ply prepared as a prior, the
// other session's map.ply and trajectory.tum placed into it by
// slam::join_session, and what came of it written where `adit sessions` and
// the crew find it:
//   <session>/joined.json  on success: joined_to (the stored session's folder
//                          name), stored_from_new (x y z qx qy qz qw), the places
//   <out>/map.ply, trajectory.tum   (when asked) both sessions in the stored
//                          one's frame: a folder that can itself be joined to
// Used by `adit join` and by aditd after a session (session.join_previous).

#include <atomic>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "adit/slam/session_join.hpp"

namespace adit::products {

inline constexpr const char* kJoinedFile = "joined.json";

struct JoinFilesOptions {
  slam::SessionJoinConfig config;
  // The search sees the session moved by this first (a check that it never
  // relies on two sessions starting at the same place); the transform
  // reported is for the session as it is.
  Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
  std::filesystem::path out;                // empty: no joined folder
  const std::atomic<bool>* cancel = nullptr;  // checked between places
};

struct JoinFilesReport {
  slam::SessionJoinResult result;
  std::string stored_name;  // the stored session's folder name
  std::string json;         // what joined.json holds (written only on success)
};

// Throws adit::InputError naming the file when a map or trajectory cannot be
// read or is empty, or when the stored map cannot serve as a prior.
JoinFilesReport join_session_folders(const std::filesystem::path& session, const std::filesystem::path& stored,
                                     const JoinFilesOptions& options = {});

// After a session: joins it to the newest earlier session in the same
// sessions folder whose map it overlaps, trying at most `tries` earlier
// sessions with a map.ply and a trajectory.tum, newest first (folder names
// are start times). One report per try, the last successful when one is;
// a try that cannot read its files is reported as failed with the reason.
std::vector<JoinFilesReport> join_previous_session(const std::filesystem::path& session, int tries = 3,
                                                   const JoinFilesOptions& options = {});

// A folder's name, also when it was given with a trailing slash.
std::string folder_name(const std::filesystem::path& dir);

}  // namespace adit::products
