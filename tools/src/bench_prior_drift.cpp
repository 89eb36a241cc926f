#include "bench_prior_drift.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <vector>

#include "adit/common/error.hpp"
#include "adit/common/quantile.hpp"
#include "adit/config/load.hpp"
#include "adit/daemon/can_feed.hpp"
#include "adit/daemon/extrinsics.hpp"
#include "adit/daemon/scan_odometry.hpp"
#include "adit/eval/align.hpp"
#include "adit/eval/associate.hpp"
#include "adit/eval/path.hpp"
#include "adit/eval/pose_error.hpp"
#include "adit/eval/trajectory_io.hpp"
#include "adit/slam/anchor_confirmation.hpp"
#include "adit/slam/global_localisation.hpp"
#include "adit/slam/trajectory.hpp"
#include "bench_scans.hpp"

namespace adit::tools {
namespace {

// Positions (and rotations) against the truth's, associated by time, no fit.
void score(const slam::Trajectory& truth, const slam::Trajectory& estimate, DriftRun& run) {
  const eval::Associated a = eval::associate(truth, estimate, 0.02);
  if (a.ref.empty()) throw InputError("truth_body.tum", "", "no truth pose within 20 ms of an estimate");
  double sum2 = 0.0;
  for (std::size_t i = 0; i < a.ref.size(); ++i) {
    const Eigen::Isometry3d e = a.ref[i].inverse() * a.est[i];
    const double d = (a.ref[i].translation() - a.est[i].translation()).norm();
    sum2 += d * d;
    run.ape_max_m = std::max(run.ape_max_m, d);
    run.ape_max_deg = std::max(run.ape_max_deg, eval::rad_to_deg(eval::rotation_angle(e.linear())));
  }
  run.ape_rms_m = std::sqrt(sum2 / static_cast<double>(a.ref.size()));
  // The shape alone: after the rigid fit that best places the run on the truth.
  run.ape_fitted_rms_m = std::numeric_limits<double>::quiet_NaN();
  if (const auto fit = eval::align_trajectory(a.ref, a.est, eval::Alignment::se3)) {
    double fitted2 = 0.0;
    for (std::size_t i = 0; i < a.ref.size(); ++i) {
      const Eigen::Vector3d p = fit->rotation * a.est[i].translation() + fit->translation;
      fitted2 += (a.ref[i].translation() - p).squaredNorm();
    }
    run.ape_fitted_rms_m = std::sqrt(fitted2 / static_cast<double>(a.ref.size()));
  }
  run.path_m = eval::path_length(a.ref);
  run.end_error_m = (a.ref.back().translation() - a.est.back().translation()).norm();
  run.drift_percent = run.path_m > 0.0 ? 100.0 * run.end_error_m / run.path_m : 0.0;
}

DriftRun run_odometry(const std::filesystem::path& session, std::span<const BenchScan> scans,
                      const slam::Trajectory& truth, const slam::PriorMap* prior, const slam::VoxelHashMap* index,
                      const Eigen::Isometry3d& world_from_prior, int scans_per_try, double prior_sigma_m, int prior_stride) {
  config::Config payload = config::load_config(session / "session.yaml");
  std::size_t most_points = 1;
  for (const BenchScan& s : scans) most_points = std::max(most_points, s.points.size());
  slam::OdometryConfig config = daemon::odometry_config_of(payload, slam::OdometryConfig{}, most_points);
  if (prior_sigma_m > 0.0) config.prior_map_sigma_m = prior_sigma_m;
  if (prior_stride > 0) config.prior_map_stride = prior_stride;
  std::unique_ptr<daemon::CanFeed> can;
  const bool can_imu = payload.imu.enabled && payload.imu.source == config::ImuSource::can;
  if (payload.can.enabled && (payload.wheel_odometry.enabled || can_imu)) {
    can = std::make_unique<daemon::CanFeed>(payload);
    can->start({});
  }
  daemon::ScanOdometry odometry(payload, config, can.get(), [] { return true; });
  drivers::LidarScan lidar_scan;
  lidar_scan.points.reserve(most_points);

  DriftRun run;
  slam::Trajectory odometry_poses;
  std::vector<double> ms;
  std::vector<Eigen::Vector3f> cloud;  // the scans since the last try, odometry frame
  int since_try = 0;
  slam::AnchorConfirmation confirmation;
  Eigen::Isometry3d prior_from_odometry = Eigen::Isometry3d::Identity();
  const double t0 = scans.empty() ? 0.0 : 1e-9 * static_cast<double>(scans.front().stamp_ns);
  for (const BenchScan& scan : scans) {
    to_lidar_scan(scan, lidar_scan);
    const slam::OdometryResult& r = odometry.process(lidar_scan);
    ms.push_back(odometry.registration_ms());
    run.invalid_poses += r.valid ? 0 : 1;
    const double t = 1e-9 * static_cast<double>(scan.stamp_ns);
    odometry_poses.push_back(t, r.pose);
    if (prior == nullptr || run.anchored || !r.valid) continue;
    const auto points = odometry.odometry().last_registered_points();
    cloud.insert(cloud.end(), points.begin(), points.end());
    if (++since_try < scans_per_try) continue;
    // A levelled frame at the sensor's position now (the localisation finds
    // the floor below its origin), as a crew's start would be.
    const std::optional<Eigen::Vector3d> up = odometry.odometry().up();
    const Eigen::Vector3d sensor = r.pose * daemon::isometry_of(payload.lidar.extrinsics).translation();
    const Eigen::Isometry3d level_from_odometry =
        slam::levelled_frame_at(up.value_or(Eigen::Vector3d::UnitZ()), sensor);
    for (Eigen::Vector3f& p : cloud) p = level_from_odometry.cast<float>() * p;
    const slam::LocalisationResult found = slam::localise(cloud, *prior, *index, std::nullopt, slam::confirmed_localisation());
    ++run.localisation_tries;
    cloud.clear();
    since_try = 0;
    if (!found.success) {
      run.failure = found.failure;
      continue;
    }
    // As aditd with prior_map.confirm (its default): taken once the next try agrees.
    if (!confirmation.agrees(found.pose * level_from_odometry, level_from_odometry.inverse())) {
      run.failure = "found, waiting for the next try to agree";
      continue;
    }
    prior_from_odometry = found.pose * level_from_odometry;
    odometry.odometry().anchor_to_prior(*index, prior_from_odometry);
    run.anchored = true;
    run.anchored_at_s = t - t0;
  }
  if (can) can->stop();
  // Placed in the world: anchored, where the localisation put the odometry
  // frame; otherwise its first pose on the truth's.
  Eigen::Isometry3d world_from_odometry = world_from_prior * prior_from_odometry;
  if (!run.anchored && !odometry_poses.empty()) {
    slam::Trajectory first;
    first.push_back(odometry_poses.stamps.front(), odometry_poses.poses.front());
    const eval::Associated a = eval::associate(truth, first, 0.02);
    if (a.ref.empty()) throw InputError(session / "truth_body.tum", "", "no truth at the first scan");
    world_from_odometry = a.ref.front() * odometry_poses.poses.front().inverse();
  }
  slam::Trajectory estimate;
  for (std::size_t i = 0; i < odometry_poses.size(); ++i)
    estimate.push_back(odometry_poses.stamps[i], world_from_odometry * odometry_poses.poses[i]);
  score(truth, estimate, run);
  run.odometry_median_ms = quantile(ms, 0.5);
  run.odometry_p99_ms = quantile(ms, 0.99);
  return run;
}

}  // namespace

PriorDrift measure_prior_drift(const std::filesystem::path& session, std::span<const BenchScan> scans,
                               const slam::PriorMap& prior, const slam::VoxelHashMap& index,
                               const Eigen::Isometry3d& world_from_prior, int scans_per_try, double prior_sigma_m,
                               int prior_stride) {
  const slam::Trajectory truth = eval::read_tum(session / "truth_body.tum");
  PriorDrift drift;
  drift.without_prior = run_odometry(session, scans, truth, nullptr, nullptr, world_from_prior, scans_per_try, prior_sigma_m, prior_stride);
  drift.with_prior = run_odometry(session, scans, truth, &prior, &index, world_from_prior, scans_per_try, prior_sigma_m, prior_stride);
  return drift;
}

}  // namespace adit::tools
