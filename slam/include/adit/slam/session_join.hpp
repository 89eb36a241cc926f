#pragma once
// Joining sessions: where, in a stored session's map, does another session's
// map lie? "Start where you left off" (issue #20, part 5): a mine surveyed in
// several flights becomes one map.
//
// The stored session's map is the prior (prior_map.hpp) and the other
// session's map is cut into clouds round places along its path (the points a
// sensor there sees, within `cloud_radius_m`); each is globally localised
// against the prior (global_localisation.hpp: the plan-view correlative
// search, registration, the overlap, ambiguity and conditioning checks).
// The sessions overlap only in part, so places are tried along the whole
// path. A join needs two places, at least `confirm_apart_m` apart along the
// path, that localise to the same transform: one place can localise wrongly
// in a repetitive drift whose checks it passes; independent places agreeing
// is the pairwise-consistency test of loop closure (PCM, Mangelson et al.,
// ICRA 2018: the largest mutually consistent set) applied to the two
// sessions. Refused as ambiguous: a second set of two or more places agreeing
// on another transform, or as many places outside the set as in it.
//
// Frames: both maps levelled by gravity (z up), each in its own session's
// map frame. docs/SESSIONS.md (Joining sessions); docs/decisions/047-session-join.md.

#include <atomic>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "adit/slam/global_localisation.hpp"
#include "adit/slam/prior_map.hpp"
#include "adit/slam/trajectory.hpp"
#include "adit/slam/voxel_hash_map.hpp"

namespace adit::slam {

struct SessionJoinConfig {
  double place_spacing_m = 5.0;     // places tried every this much path
  float cloud_radius_m = 20.0F;     // a place's cloud: map points within this horizontal distance
  float cloud_height_m = 6.0F;      // ... and this far above or below the place
  float sensor_height_m = 1.0F;     // the cloud's origin this far above the trajectory's pose (a sensor's place)
  int max_places = 60;              // tried at most (spread evenly over the path beyond that)
  double confirm_apart_m = 10.0;    // two confirming places at least this far apart along the path
  double agree_m = 0.15;            // two places' transforms agree within this ...
  double agree_rad = 0.0087;        // ... and 0.5°
  LocalisationConfig localisation;  // each place's global localisation
  const std::atomic<bool>* cancel = nullptr;  // set: stop before the next place ("cancelled")
};

// One place tried along the other session's path.
struct JoinPlace {
  double path_m = 0.0;     // along the other session's path
  LocalisationResult result;
  bool agrees = false;     // in the largest set of places agreeing on one transform
};

struct SessionJoinResult {
  bool success = false;
  Eigen::Isometry3d stored_from_new = Eigen::Isometry3d::Identity();  // maps the new session's map frame into the stored one's
  std::string failure;                                                // why not, when !success
  int places_tried = 0;
  int places_localised = 0;       // succeeded on their own
  int places_agreeing = 0;        // of them, with the join's transform
  double first_agreeing_path_m = 0.0;
  double overlap = 0.0;           // the best agreeing place's
  std::vector<JoinPlace> places;  // every place tried, in path order
};

// `stored`/`index`: the stored session's map prepared as a prior
// (prepare_prior_map, index_prior_map). `new_points`, `new_trajectory`: the
// other session's map and body poses, in its own map frame.
SessionJoinResult join_session(const PriorMap& stored, const VoxelHashMap& index, std::span<const Eigen::Vector3f> new_points,
                               const Trajectory& new_trajectory, const SessionJoinConfig& config = {});

}  // namespace adit::slam
