#include "adit/sim/session.hpp"

#include <cmath>
#include <fstream>

#include "adit/common/error.hpp"
#include "adit/common/log.hpp"
#include "adit/drivers/pcap_writer.hpp"
#include "adit/sim/ray_caster.hpp"
#include "adit/sim/drone_path.hpp"
#include "adit/sim/robot_path.hpp"
#include "adit/sim/session_config.hpp"
#include "adit/sim/spinning_lidar.hpp"
#include "adit/sim/targets.hpp"
#include "adit/sim/truth.hpp"
#include "adit/sim/imu.hpp"
#include "adit/sim/wheel_encoders.hpp"
#include "adit/drivers/can/candump.hpp"

namespace adit::sim {
namespace {

void require(bool ok, const std::string& key, const std::string& reason) {
  if (!ok) throw InputError("adit sim", key, reason);
}

// Where the sensor sits: on the robot as in the VLP-16 robot template; on top of the drone.
Eigen::Isometry3d sensor_extrinsics(const std::string& platform) {
  Eigen::Isometry3d e = Eigen::Isometry3d::Identity();
  e.translation() = platform == "drone" ? Eigen::Vector3d(0.0, 0.0, 0.12) : Eigen::Vector3d(0.20, 0.0, 0.45);
  return e;
}

bool is_drone(const SimOptions& o) { return o.platform == "drone"; }

}  // namespace

Scene simulated_scene(const SimOptions& o) {
  if (o.scene == "drift") return make_drift(o.seed);
  if (o.scene == "building") return make_building(o.seed);
  return make_mine(o.seed);
}

Eigen::Isometry3d simulated_extrinsics(const SimOptions& o) { return sensor_extrinsics(o.platform); }

People simulated_people(const Scene& scene, const SimOptions& o) { return make_people(scene, o.people, o.seed); }

BodyTrack simulated_path(const Scene& scene, const SimOptions& o) {
  if (is_drone(o)) {
    DronePathOptions d;
    d.duration_s = o.duration_s;
    d.speed_mps = o.speed_mps;
    d.lateral_offset_m = o.lateral_offset_m;
    d.seed = o.seed;
    return drone_path(scene, d);
  }
  RobotPathOptions r;
  r.duration_s = o.duration_s;
  r.speed_mps = o.speed_mps;
  r.lateral_offset_m = o.lateral_offset_m;
  r.seed = o.seed;
  return robot_path(scene, r);
}

void validate(const SimOptions& o) {
  require(o.scene == "mine" || o.scene == "drift" || o.scene == "building", "--scene",
          "unknown scene '" + o.scene + "' (mine, drift, building)");
  require(o.platform == "robot" || o.platform == "drone", "--platform",
          "unknown platform '" + o.platform + "' (robot, drone)");
  const SpinningSensor sensor = make_spinning_sensor(o.sensor);  // throws for models the simulator does not have
  const double shortest = is_drone(o) ? drone_min_duration_s() : robot_min_duration_s();
  require(std::isfinite(o.duration_s) && o.duration_s >= shortest && o.duration_s <= 7200.0, "--duration",
          "must be between " + std::to_string(shortest) + " and 7200 s for the " + o.platform);
  require(!o.out.empty(), "--out", "an output folder is required");
  require(std::isfinite(o.noise_m) && o.noise_m >= 0.0 && o.noise_m <= 1.0, "--noise-m", "must be in [0, 1] m");
  require(std::isfinite(o.dropout) && o.dropout >= 0.0 && o.dropout < 1.0, "--dropout", "must be in [0, 1)");
  require(std::isfinite(o.min_range_m) && o.min_range_m >= 0.0, "--min-range-m", "must not be negative");
  require(std::isfinite(o.max_range_m) && o.max_range_m > o.min_range_m && o.max_range_m <= 130.0, "--max-range-m",
          "must exceed --min-range-m and be at most 130 m (the VLP-16's 16-bit range field)");
  require(std::isfinite(o.rpm) && o.rpm >= 300.0 && o.rpm <= 1200.0, "--rpm", "the VLP-16 turns at 300-1200 rpm");
  require(sensor.fixed_rpm == 0.0 || o.rpm == sensor.fixed_rpm, "--rpm",
          "the " + sensor.model + " turns at " + std::to_string(static_cast<int>(sensor.fixed_rpm)) +
              " rpm in its simulated lidar mode");
  const double fastest = is_drone(o) ? DronePathOptions::kMaxSpeed : RobotPathOptions::kMaxSpeed;
  require(std::isfinite(o.speed_mps) && o.speed_mps > 0.0 && o.speed_mps <= fastest, "--speed",
          "the " + o.platform + " moves at (0, " + std::to_string(fastest) + "] m/s");
  require(std::isfinite(o.lateral_offset_m), "--lateral-offset-m", "must be a number");
  require(std::isfinite(o.wheel_radius_error) && std::abs(o.wheel_radius_error) <= 0.1, "--wheel-radius-error",
          "must be within ±0.1 (±10 %)");
  require(std::isfinite(o.slips_per_minute) && o.slips_per_minute >= 0.0 && o.slips_per_minute <= 60.0,
          "--slips-per-minute", "must be in [0, 60]");
  require(std::isfinite(o.can_offset_s) && std::abs(o.can_offset_s) <= 10.0, "--can-offset-s", "must be within ±10 s");
  require(o.targets >= 0 && o.targets <= 50, "--targets", "must be in [0, 50]");
  require(o.people >= 0 && o.people <= 100, "--people", "must be in [0, 100]");
  require(o.threads >= 1 && o.threads <= 64, "--threads", "must be in [1, 64]");
}

SimSummary run_simulation(const SimOptions& o) {
  validate(o);
  const Scene scene = simulated_scene(o);
  const BodyTrack body = simulated_path(scene, o);
  // The platform (about 0.6 m wide) must stay clear of the walls, floor and roof all the way.
  double path_length = 0.0;
  for (std::size_t i = 0; i < body.samples().size(); ++i) {
    const Eigen::Vector3d& p = body.samples()[i].position;
    if (scene.plan.distance(p.head<2>()) > -0.4 || p.z() > scene.plan.roof(p.head<2>()) - 0.5) {
      throw InputError("adit sim", "--lateral-offset-m",
                       "the path leaves the " + scene.name + " at t = " + std::to_string(static_cast<double>(i) / BodyTrack::kRate) +
                           " s (x " + std::to_string(p.x()) + ", y " + std::to_string(p.y()) + ")");
    }
    if (i > 0) path_length += (p - body.samples()[i - 1].position).norm();
  }

  std::filesystem::create_directories(o.out);
  const RayCaster caster(scene.mesh);
  const std::vector<Target> targets = place_targets(scene, caster, o.targets);

  const SpinningSensor sensor = make_spinning_sensor(o.sensor);
  {
    std::ofstream out(o.out / sensor.calibration_file, std::ios::trunc);
    out << sensor.calibration_text;
    if (!out) throw InputError((o.out / sensor.calibration_file).string(), "", "could not write the calibration");
  }
  LidarSimOptions lidar;
  lidar.effects.range_sigma_m = o.noise_m;
  lidar.effects.dropout = o.dropout;
  lidar.effects.min_range_m = o.min_range_m;
  lidar.effects.max_range_m = o.max_range_m;
  lidar.rpm = o.rpm;
  lidar.seed = o.seed;
  lidar.start_time_ns = o.start_time_ns;
  lidar.extrinsics = sensor_extrinsics(o.platform);
  lidar.threads = o.threads;
  drivers::PcapWriter pcap(o.out / "lidar.pcap");
  const People people = simulated_people(scene, o);
  const LidarSimStats stats = simulate_spinning_lidar(sensor, body, caster, scene.mesh, targets, people, lidar, pcap);
  pcap.flush();

  WheelOptions wheels;
  wheels.radius_error = o.wheel_radius_error;
  wheels.slips_per_minute = o.slips_per_minute;
  wheels.time_offset_s = o.can_offset_s;
  wheels.start_time_ns = o.start_time_ns;
  wheels.seed = o.seed;
  ImuOptions imu;
  imu.bias_sigma_mps2 = o.imu_bias_sigma_mps2;
  imu.time_offset_s = o.can_offset_s;
  imu.start_time_ns = o.start_time_ns;
  imu.seed = o.seed;
  if (o.wheels && !is_drone(o)) {
    std::vector<drivers::can::Frame> frames;
    const WheelTruth truth = simulate_wheel_encoders(body, wheels, frames);
    write_wheel_truth(o.out / "truth_wheels.csv", truth, o.start_time_ns);
    if (o.imu) {
      const ImuTruth imu_truth = simulate_imu(body, imu, frames);
      log::info("sim: accelerometer bias {:+.4f} {:+.4f} {:+.4f} m/s²", imu_truth.bias.x(), imu_truth.bias.y(),
                imu_truth.bias.z());
    }
    std::stable_sort(frames.begin(), frames.end(), [](const auto& a, const auto& b) { return a.time_us < b.time_us; });
    drivers::can::CandumpWriter writer(o.out / "can.log");
    for (const drivers::can::Frame& f : frames) writer.write(f);
    writer.flush();
  }
  write_tum(o.out / "truth_body.tum", body, Eigen::Isometry3d::Identity(), o.start_time_ns);
  write_tum(o.out / "truth_sensor.tum", body, lidar.extrinsics, o.start_time_ns);
  write_ply(o.out / "scene.ply", scene.mesh);
  if (!scene.design.triangles.empty()) write_ply_points(o.out / "bim.ply", sample_surface(scene.design, 100.0, o.seed));
  write_targets_csv(o.out / "targets.csv", targets);
  write_session_config(o.out / "session.yaml", o, sensor.calibration_file, wheels, imu, lidar.extrinsics);

  SimSummary summary;
  summary.packets = stats.packets;
  summary.returns = stats.returns;
  summary.triangles = scene.mesh.triangles.size();
  summary.targets = targets.size();
  summary.path_length_m = path_length;
  log::info("sim: {} {} s, {} packets, {} returns, {} triangles, path {:.1f} m", scene.name, o.duration_s,
            summary.packets, summary.returns, summary.triangles, path_length);
  return summary;
}

}  // namespace adit::sim
