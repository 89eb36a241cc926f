// adit bench odometry: per-scan odometry time (median, p99), speed as a
// multiple of real time, memory, drift against ground truth when given, and a
// baseline (PCL GICP) on the same scans in the same run, with the ratio.
// (adit bench pipeline lives in bench_pipeline.cpp.)

#include <algorithm>
#include <fstream>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "adit/common/clock.hpp"
#include "adit/common/error.hpp"
#include "adit/common/quantile.hpp"
#include "adit/config/load.hpp"
#include "adit/daemon/can_feed.hpp"
#include "adit/daemon/scan_odometry.hpp"
#include "adit/eval/align.hpp"
#include "adit/eval/ape.hpp"
#include "adit/eval/associate.hpp"
#include "adit/eval/kitti_drift.hpp"
#include "adit/eval/path.hpp"
#include "adit/eval/stats.hpp"
#include "adit/eval/trajectory_io.hpp"
#include "adit/slam/odometry.hpp"
#include "adit/slam/trajectory.hpp"
#include "adit/slam/tum.hpp"
#include "bench_attitude.hpp"
#include "bench_baseline.hpp"
#include "bench_pipeline.hpp"
#include "bench_loops.hpp"
#include "bench_prior_map.hpp"
#include "bench_scans.hpp"
#include "commands.hpp"
#include "process_memory.hpp"

namespace adit::tools {
namespace {

struct BenchOptions {
  BenchInput input;
  std::string truth;
  std::string out;
  std::string baseline_out;
  std::string baseline = "gicp";
  std::string config_file;  // the payload's config (aditd's): extrinsics, ranges, CAN wheels and accelerometer
  std::string imu = "on";  // off: the config's IMU ignored (LiDAR only, or LiDAR + wheels), for comparison
  double scan_period_s = 0.0;  // 0 = from the scans' stamps
  float max_range_m = 100.0F;
  float map_voxel_m = 0.5F;
  float map_point_spacing_m = slam::OdometryConfig{}.map_point_spacing_m;
  double degeneracy_threshold = slam::RegistrationConfig{}.degeneracy_threshold;
  double point_sigma_m = slam::RegistrationConfig{}.point_sigma_m;
  int plane_neighbors = slam::RegistrationConfig{}.plane_neighbors;
  bool fixed_sweep_velocity = false;  // deskew with the prediction's velocity only
  double sweep_velocity_sigma_radps = slam::OdometryConfig{}.sweep_velocity_sigma_radps;
  std::size_t target_registration_points = slam::OdometryConfig{}.target_registration_points;
  double max_turn_rate_radps = slam::OdometryConfig{}.max_turn_rate_radps;
  double narrow_below_step = slam::RegistrationConfig{}.narrow_below_step;
};

template <typename F>
double time_ms(F&& f) {
  const std::int64_t t0 = monotonic_ns();
  f();
  return 1e-6 * static_cast<double>(monotonic_ns() - t0);
}

// Drift of `est` against the reference, the KITTI way over 100–800 m segments,
// or, for shorter paths, the end-to-end error over the path length.
void print_drift(const std::string& label, const slam::Trajectory& truth, const slam::Trajectory& est) {
  const eval::Associated a = eval::associate(truth, est, 0.02);
  if (a.pairs.size() < 2) {
    fmt::print("{}: no poses associated with the ground truth within 20 ms\n", label);
    return;
  }
  // APE after an SE(3) fit as well: a drift figure alone can look good for an
  // estimate that went wrong and came back (or never moved on an out-and-back path).
  if (const auto fit = eval::align_trajectory(a.ref, a.est, eval::Alignment::se3)) {
    std::vector<slam::Pose> aligned;
    for (const auto& pose : a.est) aligned.push_back(fit->apply(pose));
    const eval::PoseErrors errors = eval::absolute_pose_errors(a.ref, aligned);
    const eval::Stats ape = eval::compute_stats(errors.translation);
    const eval::Stats attitude = eval::compute_stats(errors.rotation_deg);
    fmt::print("{}: APE (SE(3)-aligned) rmse {:.3f} m, max {:.3f} m over {} poses; attitude rmse {:.3f} deg, max {:.3f} deg\n",
               label, ape.rmse, ape.max, ape.count, attitude.rmse, attitude.max);
  }
  if (const auto kitti = eval::kitti_drift(a.ref, a.est)) {
    fmt::print("{}: drift {:.3f} % and {:.4f} deg/100 m (KITTI, {} segments of 100-800 m)\n", label,
               kitti->translation_percent, kitti->rotation_deg_per_100m, kitti->segments);
    return;
  }
  const double length = eval::path_length(a.ref);
  const Eigen::Isometry3d ref_delta = a.ref.front().inverse() * a.ref.back();
  const Eigen::Isometry3d est_delta = a.est.front().inverse() * a.est.back();
  const double error = (ref_delta.inverse() * est_delta).translation().norm();
  fmt::print("{}: end-to-end error {:.3f} m over {:.1f} m of path = {:.3f} % (path shorter than 100 m)\n", label, error,
             length, length > 0 ? 100.0 * error / length : 0.0);
}

int bench_odometry(const BenchOptions& o) {
  const std::vector<BenchScan> scans = load_bench_scans(o.input);
  if (scans.size() < 2) throw InputError(o.input.scans_dir + o.input.pcap, "", "fewer than 2 scans to benchmark");
  std::vector<double> gaps;
  for (std::size_t i = 1; i < scans.size(); ++i) gaps.push_back(1e-9 * static_cast<double>(scans[i].stamp_ns - scans[i - 1].stamp_ns));
  const double period_s = o.scan_period_s > 0.0 ? o.scan_period_s : quantile(gaps, 0.5);
  std::vector<double> sizes;
  for (const auto& s : scans) sizes.push_back(static_cast<double>(s.points.size()));
  fmt::print("scans: {} with {:.0f} points each (median), one every {:.1f} ms\n", scans.size(), quantile(sizes, 0.5),
             1e3 * period_s);

  slam::OdometryConfig config;
  config.max_range_m = o.max_range_m;
  config.map_voxel_m = o.map_voxel_m;
  config.registration_voxel_m = 1.5F * o.map_voxel_m;
  config.map_point_spacing_m = o.map_point_spacing_m;
  config.registration.degeneracy_threshold = o.degeneracy_threshold;
  config.registration.point_sigma_m = o.point_sigma_m;
  config.registration.plane_neighbors = o.plane_neighbors;
  config.estimate_sweep_velocity = !o.fixed_sweep_velocity;
  config.sweep_velocity_sigma_radps = o.sweep_velocity_sigma_radps;
  config.target_registration_points = o.target_registration_points;
  config.max_turn_rate_radps = o.max_turn_rate_radps;
  config.registration.narrow_below_step = o.narrow_below_step;
  const auto most_points = static_cast<std::size_t>(quantile(sizes, 1.0));
  config.max_scan_points = std::max<std::size_t>(most_points, 1);  // room for the largest, as aditd for its sensor
  // The payload as aditd reads it: its extrinsics, ranges and CAN bus; or
  // none (sensor frame, no wheels, no accelerometer).
  config::Config payload;
  std::unique_ptr<daemon::CanFeed> can;
  if (!o.config_file.empty()) {
    payload = config::load_config(o.config_file);
    if (o.imu == "off") payload.imu.enabled = false;
    config = daemon::odometry_config_of(payload, config, most_points);
    const bool can_imu = payload.imu.enabled && payload.imu.source == config::ImuSource::can;
    if (payload.can.enabled && (payload.wheel_odometry.enabled || can_imu)) {
      can = std::make_unique<daemon::CanFeed>(payload);
      can->start({});
    }
    fmt::print("payload: {} (body frame; {}{})\n", o.config_file, can && can->has_wheels() ? "CAN wheels" : "no wheels",
               can && can->has_imu() ? (payload.imu.gyro_x_signal.empty() ? ", CAN accelerometer" : ", CAN IMU") : "");
  }
  const double rss_before = resident_mb();
  daemon::ScanOdometry odometry(payload, config, can.get(), [] { return true; });
  drivers::LidarScan lidar_scan;
  lidar_scan.points.reserve(most_points);
  slam::Trajectory estimate;
  std::vector<double> ms;
  std::size_t degenerate = 0;
  std::size_t invalid = 0;
  std::vector<double> iterations;
  std::vector<double> used_points;
  std::vector<double> voxels;
  std::vector<double> weakest;
  std::size_t wheel_rejected = 0;
  std::size_t inertial = 0;
  std::size_t standstill = 0;
  std::size_t lost = 0;
  std::size_t relocalised = 0;
  for (const BenchScan& scan : scans) {
    to_lidar_scan(scan, lidar_scan);
    const slam::OdometryResult& r = odometry.process(lidar_scan);
    ms.push_back(odometry.registration_ms());
    degenerate += r.status == slam::OdometryStatus::degenerate ? 1 : 0;
    invalid += r.valid ? 0 : 1;
    lost += r.status == slam::OdometryStatus::lost ? 1 : 0;
    relocalised += r.status == slam::OdometryStatus::relocalised ? 1 : 0;
    wheel_rejected += r.wheel_rejected ? 1 : 0;
    inertial += r.inertial ? 1 : 0;
    standstill += r.standstill ? 1 : 0;
    iterations.push_back(r.registration.iterations);
    used_points.push_back(static_cast<double>(r.registration_points));
    if (r.registration_points > 0) voxels.push_back(r.registration_voxel_m);
    if (r.status == slam::OdometryStatus::ok || r.status == slam::OdometryStatus::degenerate)
      weakest.push_back(r.registration.weakest_eigenvalue);
    // With --spin the added turn is taken back out: the trajectory compares with the run without it.
    estimate.push_back(1e-9 * static_cast<double>(scan.stamp_ns),
                       r.pose * Eigen::AngleAxisd(-scan.spin_rad, Eigen::Vector3d::UnitZ()));
  }
  if (can) {
    can->stop();
    const daemon::CanFeedStats& feed = can->stats();
    const daemon::MotionAidCounts& counts = odometry.counts();
    if (can->has_wheels())
      fmt::print("wheels: {} samples ({} not trusted; {} wheel slips held); {} scans with their prior, {} outside the "
                 "wheel log on constant velocity; the prior disagreed with the scan on {} scans (constant velocity used)\n",
                 feed.samples.load(), feed.untrusted.load(), feed.slip_episodes.load(), counts.wheel_priors,
                 counts.scans_without_wheels, wheel_rejected);
    if (can->has_imu()) {
      const daemon::ImuStats& imu = can->imu_stats();
      fmt::print("IMU: {} readings ({} with gyro) at {:.1f} Hz; gravity's up held {} scans, {} without; {} scans "
                 "LiDAR-inertial, {} of them still (a zero-velocity update)\n",
                 imu.samples.load(), imu.gyro_samples.load(), imu.rate_hz.load(), counts.gravity_priors,
                 counts.scans_without_gravity, inertial, standstill);
      if (const std::string problems = daemon::describe_problems(imu, "can"); !problems.empty())
        fmt::print("{}\n", problems);
    }
  }
  const double median = quantile(ms, 0.5);
  fmt::print("adit odometry: median {:.2f} ms, p99 {:.2f} ms per scan = {:.1f}x real time; "
             "{} degenerate, {} invalid ({} lost, {} relocalised); resident +{:.0f} MB (map and buffers), process peak {:.0f} MB\n"
             "  registration: {:.0f} points (at most {:.0f}) at {:.2f} m voxels, {:.0f} iterations per scan (medians); weakest direction's "
             "eigenvalue median {:.4f}, 10th percentile {:.4f} (degenerate below {})\n",
             median, quantile(ms, 0.99), 1e3 * period_s / median, degenerate, invalid, lost, relocalised, resident_mb() - rss_before,
             peak_resident_mb(), quantile(used_points, 0.5), quantile(used_points, 1.0), voxels.empty() ? 0.0 : quantile(voxels, 0.5), quantile(iterations, 0.5), quantile(weakest, 0.5),
             quantile(weakest, 0.1), o.degeneracy_threshold);
  fmt::print("adit path: {:.2f} m\n", eval::path_length(estimate.poses));
  if (!o.out.empty()) {
    std::ofstream out(o.out);
    slam::write_tum(out, estimate);
  }

  std::optional<slam::Trajectory> truth;
  if (!o.truth.empty()) {
    truth = eval::read_tum(o.truth);
    print_drift("adit odometry", *truth, estimate);
  }

  if (o.baseline == "gicp") {
    auto baseline = make_pcl_gicp_baseline(o.map_voxel_m, o.max_range_m);
    if (!baseline) {
      fmt::print("baseline: this build has no PCL (install libpcl-dev and reconfigure)\n");
      return kExitOk;
    }
    slam::Trajectory baseline_estimate;
    std::vector<double> baseline_ms;
    for (const BenchScan& scan : scans) {
      Eigen::Isometry3d pose;
      baseline_ms.push_back(time_ms([&] { pose = baseline->process(scan.points); }));
      baseline_estimate.push_back(1e-9 * static_cast<double>(scan.stamp_ns), pose);
    }
    const double baseline_median = quantile(baseline_ms, 0.5);
    fmt::print("baseline PCL GICP (scan-to-scan, voxel {:.2f} m): median {:.2f} ms, p99 {:.2f} ms per scan; "
               "adit is {:.1f}x faster (median)\n",
               o.map_voxel_m, baseline_median, quantile(baseline_ms, 0.99), baseline_median / median);
    if (truth) print_drift("baseline PCL GICP", *truth, baseline_estimate);
    if (!o.baseline_out.empty()) {
      std::ofstream out(o.baseline_out);
      slam::write_tum(out, baseline_estimate);
    }
  }
  return kExitOk;
}

}  // namespace

void register_bench_commands(CLI::App& app, int& status) {
  CLI::App* bench = app.add_subcommand("bench", "Measure speed and accuracy");
  bench->require_subcommand(1);
  auto o = std::make_shared<BenchOptions>();
  CLI::App* odometry = bench->add_subcommand(
      "odometry", "Odometry time per scan (median, p99), × real time, memory, drift, and a PCL GICP baseline");
  auto* scans = odometry->add_option("--scans", o->input.scans_dir, "Directory of PCD or KITTI .bin scans");
  auto* pcap = odometry->add_option("--pcap", o->input.pcap, "Capture to decode (with --model and --calibration)");
  scans->excludes(pcap);
  odometry->add_option("--model", o->input.model, "LiDAR model of the capture (VLP-16, PandarXT32, ...)");
  odometry->add_option("--calibration", o->input.calibration, "Calibration or metadata file of the capture");
  odometry->add_option("--max-scans", o->input.max_scans, "Use at most this many scans (0 = all)");
  odometry->add_option("--every", o->input.every, "Keep one scan in this many (larger steps between scans)")
      ->check(CLI::PositiveNumber);
  odometry->add_option("--spin-deg", o->input.spin_deg,
                       "Turn the sensor about its z by a random step within ±this from one scan to the next, on top of "
                       "its own motion (fast hand-held turns put into real scans); --out takes the turn back out")
      ->check(CLI::NonNegativeNumber);
  odometry->add_option("--spin-seed", o->input.spin_seed, "Seed of --spin-deg's steps")->capture_default_str();
  odometry->add_option("--spin-from", o->input.spin_from, "First scan (counted after --every) that --spin-deg turns")
      ->capture_default_str();
  odometry->add_option("--max-turn-rate", o->max_turn_rate_radps,
                       "Fastest turn the rotation search covers between two scans, rad/s (0 = no rotation search)")
      ->capture_default_str();
  odometry->add_option("--narrow-below-step", o->narrow_below_step,
                       "The registration kernel halves only after an update below this, m and rad (inf: every "
                       "iteration, as before decision 042)")
      ->capture_default_str();
  odometry->add_option("--truth", o->truth, "Ground-truth trajectory (TUM) for drift");
  odometry->add_option("--out", o->out, "Write adit's trajectory (TUM) here");
  odometry->add_option("--baseline-out", o->baseline_out, "Write the baseline's trajectory (TUM) here");
  odometry->add_option("--baseline", o->baseline, "gicp (PCL Generalized-ICP, scan to scan) or none")
      ->check(CLI::IsMember({"gicp", "none"}));
  odometry->add_option("--config,--wheels", o->config_file,
                       "Payload config as aditd reads it (e.g. the session.yaml of adit sim): the odometry runs in the "
                       "body frame with its extrinsics and range limits, and with the wheels and accelerometer of its "
                       "CAN bus when configured (--max-range then comes from lidar.max_range_m)");
  odometry->add_option("--imu", o->imu,
                       "on: the config's IMU as aditd uses it (LiDAR-inertial without wheels, gravity with them); "
                       "off: ignored, to compare")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  odometry->add_option("--scan-period", o->scan_period_s, "Seconds per scan (default: from the scans' stamps)");
  odometry->add_option("--max-range", o->max_range_m, "Maximum range used, m (default 100)");
  odometry->add_option("--map-voxel", o->map_voxel_m, "Local map voxel, m (default 0.5)");
  odometry->add_option("--map-point-spacing", o->map_point_spacing_m,
                       "Minimum distance between two points of one map voxel, m (0 = none, KISS-ICP: voxel / sqrt(20))")
      ->check(CLI::NonNegativeNumber);
  odometry->add_option("--degeneracy-threshold", o->degeneracy_threshold,
                       "Normalised Hessian eigenvalue below which a direction counts as unconstrained");
  odometry->add_option("--point-sigma", o->point_sigma_m,
                       "σ of one point-to-plane residual, m: weighs the scan against the motion prior");
  odometry->add_option("--plane-neighbors", o->plane_neighbors, "Map points each local plane is fitted through (3-16)")
      ->check(CLI::Range(3, 16));
  odometry->add_flag("--fixed-sweep-velocity", o->fixed_sweep_velocity,
                     "Deskew with the prediction's velocity instead of estimating each sweep's (before continuous-time registration)");
  odometry->add_option("--sweep-velocity-sigma", o->sweep_velocity_sigma_radps,
                       "σ of the sweep's angular velocity around the constant-velocity prediction, rad/s (without wheels)");
  odometry->add_option("--registration-points", o->target_registration_points,
                       "Registration points per scan the downsampling adapts its voxel to (0 = fixed 1.5 x map voxel)")
      ->capture_default_str();
  odometry->callback([o, &status] {
    if (o->input.scans_dir.empty() && o->input.pcap.empty())
      throw InputError("", "--scans/--pcap", "give a scan directory or a capture");
    status = bench_odometry(*o);
  });
  add_bench_pipeline_command(*bench, status);
  add_bench_attitude_command(*bench, status);
  add_bench_prior_map_command(*bench, status);
  add_bench_loops_command(*bench, status);
}

}  // namespace adit::tools
