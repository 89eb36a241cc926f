// adit calibrate-mounting: the LiDAR's rotation and planar lever arm on a
// wheeled robot (lidar.extrinsics) from one drive: aditd's trajectory against
// the wheels of the same drive (eval/wheel_mounting.hpp).

#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/config/load.hpp"
#include "adit/daemon/can_feed.hpp"
#include "adit/daemon/extrinsics.hpp"
#include "adit/eval/wheel_mounting.hpp"
#include "adit/slam/tum.hpp"
#include "bench_scans.hpp"
#include "commands.hpp"

namespace adit::tools {
namespace {

struct Options {
  std::string config;
  std::string trajectory;
  std::string pcap;                 // empty: the config's lidar.pcap
  bool no_floor = false;
  std::size_t every = 10;           // scans: one in this many is searched for the floor
  std::optional<double> body_height;  // m: the body frame's origin above the floor
  double window = 1.0;
};

constexpr double kDeg = 180.0 / std::numbers::pi;

// The drive's wheel poses as aditd integrates them: the config's CAN log
// replayed through the CAN feed (its decoding, slip handling and time offset).
// The drive may have been mapped without the wheels (wheel_odometry.enabled
// false, the LiDAR's own trajectory): their section still describes them.
std::vector<slam::WheelSample> wheel_poses(config::Config c, const std::string& config_file) {
  if (!c.can.enabled) throw InputError(config_file, "can.enabled", "the wheels are read from the CAN log: enable it");
  if (c.can.source != config::CanSource::candump)
    throw InputError(config_file, "can.source", "must be candump: the drive's CAN log is replayed");
  if (c.wheel_odometry.left_signal.empty() || c.wheel_odometry.right_signal.empty())
    throw InputError(config_file, "wheel_odometry.left_signal", "the wheels' signals are needed");
  c.wheel_odometry.enabled = true;
  c.imu.enabled = false;
  daemon::CanFeed feed(c);
  feed.start({});
  slam::WheelHistory history(8192);  // 80 s at 100 Hz: drained ten seconds at a time
  std::vector<slam::WheelSample> out;
  const std::function<bool()> wait = [] { return true; };
  // The first call takes one sample (any time passes -1e300); each next one
  // ten seconds more, until the log ends short of them.
  for (double until = -1e300;; until = history.latest() + 10.0) {
    feed.drain_into(history, until, nullptr, wait);
    for (std::size_t i = 0; i < history.size(); ++i)
      if (out.empty() || history[i].t > out.back().t) out.push_back(history[i]);
    if (history.latest() < until) break;
  }
  feed.stop();
  return out;
}

// The floor under the sensor in one scan of every `every` of the capture,
// `up` the body's vertical as the turns show it.
std::optional<eval::GroundSummary> floor_of(const config::Config& c, const Options& o, const Eigen::Vector3d& up,
                                            std::size_t& scans) {
  BenchInput input;
  input.pcap = o.pcap.empty() ? c.lidar.pcap : o.pcap;
  input.model = c.lidar.model;
  input.calibration = c.lidar.calibration;
  input.every = o.every;
  if (input.pcap.empty()) throw InputError(o.config, "lidar.pcap", "no capture to find the floor in: give --pcap or --no-floor");
  const std::vector<BenchScan> loaded = load_bench_scans(input);
  scans = loaded.size();
  std::vector<eval::GroundPlane> planes;
  for (const BenchScan& scan : loaded)
    if (const auto g = eval::find_ground(scan.points, up, {})) planes.push_back(*g);
  return eval::combine_ground(planes);
}

// aditd's trajectory is the body's; the sensor is where the config put it.
slam::Trajectory sensor_poses(const std::string& file, const Eigen::Isometry3d& body_from_sensor) {
  slam::Trajectory t = slam::read_tum(file);
  for (slam::Pose& pose : t.poses) pose = pose * body_from_sensor;
  return t;
}

int run(const Options& o) {
  const config::Config c = config::load_config(o.config);
  const Eigen::Isometry3d configured = daemon::isometry_of(c.lidar.extrinsics);
  const slam::Trajectory sensor = sensor_poses(o.trajectory, configured);
  const std::vector<slam::WheelSample> wheels = wheel_poses(c, o.config);
  eval::MountingOptions options;
  options.window = o.window;
  eval::MountingResult r;
  std::optional<eval::GroundSummary> floor;
  std::size_t scans = 0;
  try {
    r = eval::calibrate_mounting(sensor, wheels, options);
    if (!o.no_floor) {
      floor = floor_of(c, o, r.rotation.transpose() * Eigen::Vector3d::UnitZ(), scans);
      if (floor) r = eval::calibrate_mounting(sensor, wheels, options, floor);
    }
  } catch (const std::invalid_argument& e) {
    throw InputError(o.trajectory, "--trajectory", e.what());
  }
  const double z = floor && o.body_height ? floor->height - *o.body_height : configured.translation().z();
  const Eigen::Vector3d was = slam::rpy_of(configured.linear()) * kDeg;
  const Eigen::Vector3d rpy = r.rpy * kDeg;
  const Eigen::Vector3d sd = r.rpy_sd * kDeg;
  fmt::print("sensor poses {}, wheel samples {}, windows {} ({} turning, {} straight, {} dropped as outliers)\n",
             sensor.size(), wheels.size(), r.windows, r.turning_windows, r.straight_windows, r.outliers);
  fmt::print("roll      {:8.3f} ± {:.3f}°   (configured {:.3f}°)\n", rpy.x(), sd.x(), was.x());
  fmt::print("pitch     {:8.3f} ± {:.3f}°   (configured {:.3f}°)\n", rpy.y(), sd.y(), was.y());
  fmt::print("yaw       {:8.3f} ± {:.3f}°   (configured {:.3f}°){}\n", rpy.z(), sd.z(), was.z(),
             r.yaw_observable ? "" : "   NOT OBSERVABLE: drive straight too");
  fmt::print("x         {:8.3f} ± {:.3f} m  (configured {:.3f} m){}\n", r.lever_arm.x(), r.lever_arm_sd.x(),
             configured.translation().x(), r.lever_arm_observable ? "" : "   NOT OBSERVABLE: turn while driving");
  fmt::print("y         {:8.3f} ± {:.3f} m  (configured {:.3f} m)\n", r.lever_arm.y(), r.lever_arm_sd.y(),
             configured.translation().y());
  if (!o.no_floor && !floor) fmt::print("floor     not found in {} scans: roll and pitch from the turns alone\n", scans);
  if (floor) {
    fmt::print("floor     in {} of {} scans ({} dropped): roll and pitch from its normal, {:.3f}° from the turns' axis\n",
               floor->scans, scans, floor->outliers, r.turns_to_ground * kDeg);
    fmt::print("height    the sensor {:.3f} ± {:.3f} m above the floor\n", floor->height, floor->height_sd);
  }
  if (floor && o.body_height)
    fmt::print("z         {:8.3f} m: {:.3f} m above the floor less the body origin's {:.3f} m (configured {:.3f} m)\n", z,
               floor->height, *o.body_height, configured.translation().z());
  else
    fmt::print("z         not observable from planar driving: keep the measured {:.3f} m{}\n", configured.translation().z(),
               floor ? " (or give --body-height)" : "");
  fmt::print("residual  axis {:.5f} rad, planar {:.4f} m per {:.1f} s window (planar {:.4f} m with the sensor at the "
             "body's origin, yaw 0)\n",
             r.rms_axis, r.rms_planar, o.window, r.rms_planar_before);
  fmt::print("\nlidar:\n  extrinsics:\n    xyz_m: [{:.3f}, {:.3f}, {:.3f}]\n    rpy_deg: [{:.3f}, {:.3f}, {:.3f}]\n",
             r.lever_arm.x(), r.lever_arm.y(), z, rpy.x(), rpy.y(), rpy.z());
  return r.yaw_observable && r.lever_arm_observable ? kExitOk : kExitFailure;
}

}  // namespace

void register_calibrate_mounting_commands(CLI::App& app, int& status) {
  auto o = std::make_shared<Options>();
  CLI::App* c = app.add_subcommand(
      "calibrate-mounting",
      "Fit the LiDAR's mounting on a wheeled robot (lidar.extrinsics: roll, pitch, yaw, x, y) from a drive's "
      "trajectory against its wheels");
  c->add_option("--config", o->config, "The payload config the drive was mapped with (its can log, wheels and extrinsics)")
      ->required();
  c->add_option("--trajectory", o->trajectory, "aditd's trajectory.tum of that drive (best mapped without the wheels)")
      ->required();
  c->add_option("--pcap", o->pcap, "The drive's capture, for the floor (default: the config's lidar.pcap)");
  c->add_flag("--no-floor", o->no_floor, "Roll and pitch from the turns alone, without looking for the floor");
  c->add_option("--every", o->every, "Look for the floor in one scan of this many")->capture_default_str()->check(CLI::Range(1, 1000));
  c->add_option_function<double>(
      "--body-height", [o](double h) { o->body_height = h; },
      "The body frame's origin above the floor, m: with the floor, gives the sensor's z");
  c->add_option("--window", o->window, "Relative-motion window, s")->capture_default_str()->check(CLI::Range(0.2, 10.0));
  c->callback([o, &status] { status = run(*o); });
}

}  // namespace adit::tools
