#pragma once
// The drift half of `adit bench prior-map`: a simulated session's odometry
// (aditd's ScanOdometry with the session's payload: wheels and IMU from its
// CAN log) run twice, without the prior and anchored to it. Anchored: the
// odometry localises itself against the prior (slam::localise) from its own
// first second of scans, levelled by its own up, tries again a second later
// until it succeeds and the next try agrees (slam/anchor_confirmation.hpp, as
// aditd's prior_map.confirm), then registers every scan against the prior as well
// (slam::Odometry::anchor_to_prior). Both trajectories are scored against the
// truth with no fit: without the prior its first pose is placed on the
// truth's; anchored, its frame is where its localisation put it.

#include <filesystem>
#include <span>
#include <string>

#include <Eigen/Geometry>

#include "adit/slam/prior_map.hpp"
#include "adit/slam/voxel_hash_map.hpp"
#include "bench_scans.hpp"

namespace adit::tools {

struct DriftRun {
  bool anchored = false;        // localised against the prior (the anchored run)
  double anchored_at_s = 0.0;   // after the first scan
  int localisation_tries = 0;
  std::string failure;          // the last failed try's reason
  double path_m = 0.0;          // of the truth
  double end_error_m = 0.0;     // last position against the truth's
  double drift_percent = 0.0;   // end_error_m / path_m
  double ape_rms_m = 0.0;       // positions against the truth's, every scan
  double ape_max_m = 0.0;
  double ape_max_deg = 0.0;
  // After a rigid (SE(3)) fit to the truth: the shape without the frame's
  // placement. NaN when no fit is defined (a path along one line).
  double ape_fitted_rms_m = 0.0;
  double odometry_median_ms = 0.0;  // slam::Odometry::process per scan
  double odometry_p99_ms = 0.0;
  int invalid_poses = 0;
};

struct PriorDrift {
  DriftRun without_prior;
  DriftRun with_prior;
};

// `session`: an `adit sim` folder (session.yaml, can.log, truth_body.tum);
// `scans`: its lidar.pcap as load_bench_scans gives it. `world_from_prior` places the prior in the truth's world.
// `scans_per_try`: the scans accumulated for one localisation. Throws
// adit::InputError naming a missing or unreadable file. `prior_sigma_m` > 0
// and `prior_stride` > 0 replace slam::OdometryConfig::prior_map_sigma_m and
// prior_map_stride (to compare values).
PriorDrift measure_prior_drift(const std::filesystem::path& session, std::span<const BenchScan> scans,
                               const slam::PriorMap& prior, const slam::VoxelHashMap& index,
                               const Eigen::Isometry3d& world_from_prior, int scans_per_try, double prior_sigma_m = 0.0,
                               int prior_stride = 0);

}  // namespace adit::tools
