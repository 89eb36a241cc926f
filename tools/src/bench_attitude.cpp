// adit bench attitude (see bench_attitude.hpp). Each scan is deskewed with
// the true motion and registered three ways, always started at the true pose
// and with no prior on rotation, so that what is measured is the scan's own
// say on roll and pitch:
//   - against the previous scan alone, placed by the truth: the share of the
//     true tilt change between the two scans the registration recovers (the
//     least-squares slope of the error on the true change, plus one);
//   - against a local map of all earlier scans placed by the truth: the
//     baseline, the registration's error when its map is right;
//   - against a local map of the earlier scans placed where this same
//     registration put them, the position pinned to the truth: the tilt error
//     a scan-to-map odometry accumulates from its own map.
// The maps, voxels and registration settings are the odometry's defaults
// (slam::OdometryConfig): the scan enters the map downsampled at half the map
// voxel and is registered downsampled at the registration voxel.

#include "bench_attitude.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/eval/interpolate.hpp"
#include "adit/slam/lie.hpp"
#include "adit/slam/odometry.hpp"
#include "adit/slam/registration.hpp"
#include "adit/eval/stats.hpp"
#include "adit/eval/trajectory_io.hpp"
#include "adit/slam/voxel_downsample.hpp"
#include "adit/slam/voxel_hash_map.hpp"
#include "bench_scans.hpp"

namespace adit::tools {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

struct AttitudeOptions {
  BenchInput input;
  std::string truth;
};

// Roll and pitch errors (deg, body axes) of one registration, with the true
// change of roll and pitch since the previous scan.
struct TiltSeries {
  std::vector<double> roll, pitch, true_roll_change, true_pitch_change;

  void add(const Eigen::Isometry3d& truth, const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& change) {
    const slam::Vector6d e = slam::log_se3(truth.inverse() * estimate);
    const slam::Vector6d d = slam::log_se3(change);
    roll.push_back(kDeg * e(3));
    pitch.push_back(kDeg * e(4));
    true_roll_change.push_back(kDeg * d(3));
    true_pitch_change.push_back(kDeg * d(4));
  }
};

double rms(const std::vector<double>& v) { return eval::compute_stats(v).rmse; }

double max_abs(const std::vector<double>& v) {
  const eval::Stats s = eval::compute_stats(v);
  return std::max(std::abs(s.min), std::abs(s.max));
}

// The share of the true change recovered: 1 + the least-squares slope of the
// error on the change (1 = unbiased, 0 = the scan looks as tilted as the last).
double followed(const std::vector<double>& error, const std::vector<double>& change) {
  double ed = 0.0, dd = 0.0;
  for (std::size_t i = 0; i < error.size(); ++i) {
    ed += error[i] * change[i];
    dd += change[i] * change[i];
  }
  return dd > 0.0 ? 1.0 + ed / dd : 0.0;
}

// `points` moved to the scan start by the true motion over the sweep,
// tabulated at kBins instants (1.6 ms apart over 0.1 s). False when the truth
// does not cover the sweep.
bool deskew_by_truth(const BenchScan& scan, const slam::Trajectory& truth, const Eigen::Isometry3d& start,
                     std::vector<Eigen::Vector3f>& out) {
  constexpr int kBins = 64;
  float duration = 0.0F;
  for (std::size_t i = 0; i < scan.time_offsets_ns.size(); ++i) duration = std::max(duration, scan.time_s(i));
  std::array<Eigen::Isometry3f, kBins> table;
  const double t0 = 1e-9 * static_cast<double>(scan.stamp_ns);
  for (int b = 0; b < kBins; ++b) {
    const std::optional<slam::Pose> pose = eval::interpolate_pose(truth, t0 + duration * b / (kBins - 1.0));
    if (!pose) return false;
    table[static_cast<std::size_t>(b)] = (start.inverse() * *pose).cast<float>();
  }
  out.resize(scan.points.size());
  const bool timed = scan.time_offsets_ns.size() == scan.points.size() && duration > 0.0F;
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    const int b = timed ? static_cast<int>(std::lround(scan.time_s(i) / duration * (kBins - 1))) : 0;
    out[i] = table[static_cast<std::size_t>(std::clamp(b, 0, kBins - 1))] * scan.points[i];
  }
  return true;
}

void transform_into(std::span<const Eigen::Vector3f> in, const Eigen::Isometry3d& pose, std::vector<Eigen::Vector3f>& out) {
  const Eigen::Isometry3f T = pose.cast<float>();
  out.resize(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) out[i] = T * in[i];
}

int bench_attitude(const AttitudeOptions& o) {
  const std::vector<BenchScan> scans = load_bench_scans(o.input);
  const slam::Trajectory truth = eval::read_tum(o.truth);
  const slam::OdometryConfig odometry;
  const slam::RegistrationConfig& registration = odometry.registration;
  std::size_t most_points = 0;
  for (const BenchScan& s : scans) most_points = std::max(most_points, s.points.size());

  const auto make_map = [&] {
    return slam::VoxelHashMap(odometry.map_voxel_m, odometry.map_capacity_voxels, odometry.map_point_spacing_m);
  };
  slam::VoxelHashMap previous_map = make_map(), truth_map = make_map(), own_map = make_map();
  slam::VoxelDownsampler downsampler(most_points);
  std::vector<Eigen::Vector3f> deskewed, frame, source, placed, previous_placed;
  frame.reserve(most_points);
  source.reserve(most_points);
  std::vector<slam::MapPlane> planes(most_points);
  // Correspondences within 1 m, the robust kernel from 0.1 m down to the
  // registration's floor: a registration started at the truth needs no wider search.
  const auto register_at = [&](const slam::VoxelHashMap& map, const slam::PosePrior& prior) {
    return slam::register_scan(source, map, prior, 1.0, 0.1, registration, planes).pose;
  };

  TiltSeries against_previous, against_truth_map, against_own_map;
  Eigen::Isometry3d previous_truth = Eigen::Isometry3d::Identity(), previous_own = previous_truth;
  std::size_t used = 0, uncovered = 0;
  for (const BenchScan& scan : scans) {
    const std::optional<slam::Pose> pose = eval::interpolate_pose(truth, 1e-9 * static_cast<double>(scan.stamp_ns));
    if (!pose || !deskew_by_truth(scan, truth, *pose, deskewed)) {
      ++uncovered;
      continue;
    }
    const Eigen::Isometry3d T = *pose;
    downsampler.downsample(deskewed, 0.5F * odometry.map_voxel_m, frame);
    downsampler.downsample(frame, odometry.registration_voxel_m, source);
    Eigen::Isometry3d own = T;
    if (used > 0) {
      const Eigen::Isometry3d change = previous_truth.inverse() * T;
      slam::PosePrior at_truth;  // no information: the scan alone decides
      at_truth.mean = T;
      previous_map.clear();
      previous_map.add(previous_placed);
      against_previous.add(T, register_at(previous_map, at_truth), change);
      against_truth_map.add(T, register_at(truth_map, at_truth), change);
      // Its own chain: the rotation carried on from where it put the last
      // scan, the position pinned to the truth (σ 1 cm).
      slam::PosePrior pinned;
      pinned.mean.linear() = (previous_own * change).linear();
      pinned.mean.translation() = T.translation();
      pinned.information.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() / (0.01 * 0.01);
      own = register_at(own_map, pinned);
      against_own_map.add(T, own, change);
    }
    transform_into(frame, T, previous_placed);
    truth_map.add(previous_placed);
    transform_into(frame, own, placed);
    own_map.add(placed);
    if (used % 10 == 0) {
      truth_map.remove_far(T.translation().cast<float>(), odometry.max_range_m);
      own_map.remove_far(T.translation().cast<float>(), odometry.max_range_m);
    }
    previous_truth = T;
    previous_own = own;
    ++used;
  }
  if (used < 2) throw InputError(o.truth, "", "the ground truth covers fewer than two scans");

  fmt::print("attitude: {} scans deskewed and positioned by the truth ({} outside it); the odometry's maps and "
             "registration ({} m map voxels, {} m scan voxels, planes of {} map points)\n",
             used, uncovered, odometry.map_voxel_m, odometry.registration_voxel_m, registration.plane_neighbors);
  fmt::print("  true tilt change between scans: rms roll {:.3f}, pitch {:.3f} deg\n",
             rms(against_previous.true_roll_change), rms(against_previous.true_pitch_change));
  const auto line = [](const char* name, const TiltSeries& s) {
    fmt::print("  {:<34} roll error rms {:.3f} max {:.3f} deg, pitch rms {:.3f} max {:.3f} deg; follows {:.0f} % of "
               "the roll and {:.0f} % of the pitch change\n",
               name, rms(s.roll), max_abs(s.roll), rms(s.pitch), max_abs(s.pitch),
               100.0 * followed(s.roll, s.true_roll_change), 100.0 * followed(s.pitch, s.true_pitch_change));
  };
  line("against the previous scan alone:", against_previous);
  line("against the true map (baseline):", against_truth_map);
  line("against its own map:", against_own_map);
  const double baseline = std::hypot(rms(against_truth_map.roll), rms(against_truth_map.pitch));
  if (baseline > 0.0)
    fmt::print("  its own map's tilt error is {:.1f}x the baseline's (rms of roll and pitch)\n",
               std::hypot(rms(against_own_map.roll), rms(against_own_map.pitch)) / baseline);
  return kExitOk;
}

}  // namespace

void add_bench_attitude_command(CLI::App& bench, int& status) {
  auto o = std::make_shared<AttitudeOptions>();
  CLI::App* attitude = bench.add_subcommand(
      "attitude", "How well scan-to-map registration follows roll and pitch, given the true deskew and position");
  attitude->add_option("--pcap", o->input.pcap, "Capture to decode (with --model and --calibration)")->required();
  attitude->add_option("--model", o->input.model, "LiDAR model of the capture (VLP-16, PandarXT32, ...)")->required();
  attitude->add_option("--calibration", o->input.calibration, "Calibration or metadata file of the capture")->required();
  attitude->add_option("--truth", o->truth, "The sensor's true trajectory (TUM; adit sim's truth_sensor.tum)")
      ->required();
  attitude->add_option("--max-scans", o->input.max_scans, "Use at most this many scans (0 = all)");
  attitude->callback([o, &status] { status = bench_attitude(*o); });
}

}  // namespace adit::tools
