#include "adit/sim/session.hpp"

#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <numbers>

#include "adit/common/error.hpp"
#include "adit/common/log.hpp"
#include "adit/drivers/pcap_writer.hpp"
#include "adit/drivers/lidar/ouster_encoder.hpp"
#include "adit/sim/ray_caster.hpp"
#include "adit/sim/drone_path.hpp"
#include "adit/sim/handheld_path.hpp"
#include "adit/sim/imu_frames.hpp"
#include "adit/sim/ouster_imu_packet.hpp"
#include "adit/sim/robot_path.hpp"
#include "adit/sim/session_config.hpp"
#include "adit/sim/spinning_lidar.hpp"
#include "adit/sim/livox_lidar.hpp"
#include "adit/drivers/lidar/livox_encoder.hpp"
#include "adit/sim/targets.hpp"
#include "adit/sim/truth.hpp"
#include "adit/sim/imu.hpp"
#include "adit/sim/wheel_encoders.hpp"
#include "adit/drivers/can/candump.hpp"
#include "adit/slam/roll_pitch_yaw.hpp"

namespace adit::sim {
namespace {

void require(bool ok, const std::string& key, const std::string& reason) {
  if (!ok) throw InputError("adit sim", key, reason);
}

// Where the sensor sits: on the robot as in the VLP-16 robot template; on top
// of the drone; 0.10 m above the walker's hand (about 1.5 m above the floor);
// turned on its bracket by --mount-rpy-deg.
Eigen::Isometry3d sensor_extrinsics(const SimOptions& o) {
  Eigen::Isometry3d e = Eigen::Isometry3d::Identity();
  e.translation() = o.platform == "drone"      ? Eigen::Vector3d(0.0, 0.0, 0.12)
                    : o.platform == "handheld" ? Eigen::Vector3d(0.0, 0.0, 0.10)
                                               : Eigen::Vector3d(0.20, 0.0, 0.45);
  e.linear() = slam::rotation_from_rpy(o.mount_rpy_deg * std::numbers::pi / 180.0);
  return e;
}

bool is_drone(const SimOptions& o) { return o.platform == "drone"; }
bool is_handheld(const SimOptions& o) { return o.platform == "handheld"; }
bool is_ouster(const SimOptions& o) { return o.sensor.starts_with("OS"); }
bool is_livox(const SimOptions& o) { return o.sensor == "Mid-360"; }

DronePathOptions drone_options(const SimOptions& o) {
  DronePathOptions d;
  d.duration_s = o.duration_s;
  d.speed_mps = platform_speed_mps(o);
  d.lateral_offset_m = o.lateral_offset_m;
  d.ground_s = o.ground_s;
  d.seed = o.seed;
  return d;
}

double min_duration_s(const SimOptions& o) {
  return is_drone(o) ? drone_min_duration_s(drone_options(o)) : is_handheld(o) ? handheld_min_duration_s() : robot_min_duration_s();
}
double max_speed_mps(const SimOptions& o) {
  return is_drone(o)      ? DronePathOptions::kMaxSpeed
         : is_handheld(o) ? HandheldPathOptions::kMaxSpeed
                          : RobotPathOptions::kMaxSpeed;
}

}  // namespace

Scene simulated_scene(const SimOptions& o) {
  if (o.scene == "drift") return make_drift(o.seed);
  if (o.scene == "building") return make_building(o.seed);
  return make_mine(o.seed);
}

Eigen::Isometry3d simulated_extrinsics(const SimOptions& o) { return sensor_extrinsics(o); }

People simulated_people(const Scene& scene, const SimOptions& o) { return make_people(scene, o.people, o.seed); }

double platform_speed_mps(const SimOptions& o) {
  if (o.speed_mps > 0.0) return o.speed_mps;
  return is_handheld(o) ? HandheldPathOptions{}.speed_mps : 1.0;
}

SimImuSource simulated_imu_source(const SimOptions& o) {
  if (!o.imu) return SimImuSource::none;
  // A robot's IMU is on its CAN bus beside the wheels, whatever the LiDAR;
  // without wheels the LiDAR's own IMU (Ouster, Mid-360) is the one to read,
  // unless --imu-on-can asks for the CAN IMU (a comparison).
  if (o.platform == "robot" || o.imu_on_can) return SimImuSource::can;
  return is_ouster(o) ? SimImuSource::ouster : is_livox(o) ? SimImuSource::livox : SimImuSource::can;
}

ImuOptions simulated_imu(const SimOptions& o, SimImuSource source) {
  ImuOptions imu;
  imu.noise = o.imu_noise;
  imu.motion = o.platform == "robot" ? ImuMotion::wheeled : ImuMotion::smooth;
  imu.vibration.enabled = o.vibration == "on" || (o.vibration == "auto" && is_drone(o));
  if (source == SimImuSource::ouster) {
    // Inside the sensor, where the metadata's imu_to_sensor_transform puts it (mm).
    const drivers::OusterMetadata m = drivers::ouster_os1_64_nominal_metadata();
    Eigen::Isometry3d imu_to_sensor = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 3; ++k) imu_to_sensor.linear()(r, k) = m.imu_to_sensor[static_cast<std::size_t>(4 * r + k)];
      imu_to_sensor.translation()(r) = m.imu_to_sensor[static_cast<std::size_t>(4 * r + 3)] * 1e-3;
    }
    imu.mount = sensor_extrinsics(o) * imu_to_sensor;
    imu.rate_hz = o.imu_rate_hz > 0.0 ? o.imu_rate_hz : 100.0;
    imu.time_offset_s = o.imu_time_offset_s;  // the LiDAR's and the IMU's stamps come from one clock
    imu.seed = o.seed ^ 0x4F5374496D75ULL;    // another unit than a CAN IMU's in the same session
  } else if (source == SimImuSource::livox) {
    // Inside the sensor (livox_lidar.hpp), at its 200 Hz.
    imu.mount = sensor_extrinsics(o) * livox_mid360_imu_in_sensor();
    imu.rate_hz = 200.0;
    imu.time_offset_s = o.imu_time_offset_s;  // stamped by the sensor's clock, as its points
    imu.seed = o.seed ^ 0x4C69766F78ULL;      // another unit than a CAN IMU's
  } else {
    imu.mount.translation() = o.imu_position_m;
    imu.rate_hz = o.imu_rate_hz > 0.0 ? o.imu_rate_hz : 200.0;
    imu.time_offset_s = o.can_offset_s + o.imu_time_offset_s;
    imu.seed = o.seed;
  }
  return imu;
}

BodyTrack simulated_path(const Scene& scene, const SimOptions& o) {
  if (is_handheld(o)) {
    HandheldPathOptions h;
    h.duration_s = o.duration_s;
    h.speed_mps = platform_speed_mps(o);
    h.lateral_offset_m = o.lateral_offset_m;
    h.seed = o.seed;
    return handheld_path(scene, h);
  }
  if (is_drone(o)) return drone_path(scene, drone_options(o));
  RobotPathOptions r;
  r.duration_s = o.duration_s;
  r.speed_mps = platform_speed_mps(o);
  r.lateral_offset_m = o.lateral_offset_m;
  r.seed = o.seed;
  return robot_path(scene, r);
}

void validate(const SimOptions& o) {
  require(o.scene == "mine" || o.scene == "drift" || o.scene == "building", "--scene",
          "unknown scene '" + o.scene + "' (mine, drift, building)");
  require(o.platform == "robot" || o.platform == "drone" || o.platform == "handheld", "--platform",
          "unknown platform '" + o.platform + "' (robot, drone, handheld)");
  // Throws for models the simulator does not have.
  const SpinningSensor sensor = is_livox(o) ? SpinningSensor{} : make_spinning_sensor(o.sensor);
  const double shortest = min_duration_s(o);
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
  const double fastest = max_speed_mps(o);
  require(std::isfinite(o.speed_mps) && o.speed_mps >= 0.0 && o.speed_mps <= fastest, "--speed",
          "the " + o.platform + " moves at (0, " + std::to_string(fastest) + "] m/s (0: its own pace)");
  require(std::isfinite(o.lateral_offset_m), "--lateral-offset-m", "must be a number");
  require(o.mount_rpy_deg.allFinite() && o.mount_rpy_deg.cwiseAbs().maxCoeff() <= 180.0, "--mount-rpy-deg",
          "must be three angles within ±180°");
  require(std::isfinite(o.ground_s) && o.ground_s >= 0.0 && o.ground_s <= 60.0, "--ground-s",
          "must be 0-60 s");
  require(std::isfinite(o.wheel_radius_error) && std::abs(o.wheel_radius_error) <= 0.1, "--wheel-radius-error",
          "must be within ±0.1 (±10 %)");
  require(std::isfinite(o.slips_per_minute) && o.slips_per_minute >= 0.0 && o.slips_per_minute <= 60.0,
          "--slips-per-minute", "must be in [0, 60]");
  require(std::isfinite(o.can_offset_s) && std::abs(o.can_offset_s) <= 10.0, "--can-offset-s", "must be within ±10 s");
  require(o.imu_rate_hz == 0.0 || (o.imu_rate_hz >= 100.0 && o.imu_rate_hz <= 400.0), "--imu-rate-hz",
          "must be 0 (the source's own rate) or within [100, 400] Hz");
  const ImuNoise& n = o.imu_noise;
  const std::pair<const char*, double> noise[] = {
      {"--gyro-noise-density", n.gyro_noise_density}, {"--accel-noise-density", n.accel_noise_density},
      {"--gyro-bias-walk", n.gyro_bias_walk},         {"--accel-bias-walk", n.accel_bias_walk},
      {"--gyro-bias-sigma", n.gyro_turn_on_sigma},    {"--imu-bias-mps2", n.accel_turn_on_sigma}};
  for (const auto& [key, value] : noise)
    require(std::isfinite(value) && value >= 0.0 && value < 1.0, key, "must be in [0, 1) (SI units, see --help)");
  require(o.imu_position_m.allFinite() && o.imu_position_m.norm() <= 5.0, "--imu-position-m",
          "the IMU must sit within 5 m of the body origin");
  require(!(simulated_imu_source(o) == SimImuSource::ouster && !o.imu_position_m.isZero()), "--imu-position-m",
          "the " + o.sensor + "'s IMU sits where its metadata's imu_to_sensor_transform puts it; "
          "--imu-position-m places a CAN IMU");
  require(!(simulated_imu_source(o) == SimImuSource::livox && !o.imu_position_m.isZero()), "--imu-position-m",
          "the " + o.sensor + "'s IMU sits inside it where its manual puts it; --imu-position-m places a CAN IMU");
  require(!(simulated_imu_source(o) == SimImuSource::livox && o.imu_rate_hz != 0.0 && o.imu_rate_hz != 200.0),
          "--imu-rate-hz", "the " + o.sensor + "'s IMU sends 200 Hz");
  require(std::isfinite(o.imu_time_offset_s) && std::abs(o.imu_time_offset_s) <= 1.0, "--imu-time-offset-s",
          "must be within ±1 s");
  require(o.vibration == "auto" || o.vibration == "on" || o.vibration == "off", "--vibration",
          "unknown value '" + o.vibration + "' (auto, on, off)");
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

  const SpinningSensor sensor = is_livox(o) ? SpinningSensor{} : make_spinning_sensor(o.sensor);
  if (!is_livox(o)) {  // a Livox needs no calibration file: its packets carry Cartesian points
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
  lidar.extrinsics = sensor_extrinsics(o);
  lidar.threads = o.threads;
  const SimImuSource imu_source = simulated_imu_source(o);
  // An Ouster sends its IMU's packets beside the LiDAR's (to port 7503, from
  // the same address), merged into the pcap in capture order.
  const bool ouster_imu = o.imu && is_ouster(o);
  const ImuOptions ouster_imu_options = simulated_imu(o, SimImuSource::ouster);
  const std::vector<ImuSample> ouster_samples = ouster_imu ? simulate_imu(body, ouster_imu_options) : std::vector<ImuSample>{};
  drivers::PcapWriter pcap(o.out / "lidar.pcap");
  std::size_t imu_written = 0;
  const auto write_imu_packets = [&](std::int64_t until_ns) {
    drivers::UdpEndpoints endpoints;
    endpoints.src_port = endpoints.dst_port = drivers::ouster_os1_64_nominal_metadata().udp_port_imu;
    constexpr std::int64_t kCaptureLatencyNs = 100'000;  // as the LiDAR packets' (LidarSimOptions)
    for (; imu_written < ouster_samples.size(); ++imu_written) {
      const ImuSample& sample = ouster_samples[imu_written];
      const std::int64_t stamp_ns = o.start_time_ns + std::llround(sample.stamp * 1e9);
      if (stamp_ns + kCaptureLatencyNs > until_ns) break;
      pcap.write_udp(stamp_ns + kCaptureLatencyNs, endpoints,
                     encode_ouster_imu_packet(sample, static_cast<std::uint64_t>(stamp_ns)));
    }
  };
  const People people = simulated_people(scene, o);
  LidarSimStats stats;
  // A Mid-360 sends its IMU's SDK2 packets (200 Hz, to port 56401) beside its points, always.
  const ImuOptions livox_imu = simulated_imu(o, SimImuSource::livox);
  const std::vector<ImuSample> livox_samples = is_livox(o) ? simulate_imu(body, livox_imu) : std::vector<ImuSample>{};
  std::size_t livox_imu_written = 0;
  const auto write_livox_imu_packets = [&](std::int64_t until_ns) {
    drivers::UdpEndpoints endpoints;
    endpoints.src_port = 56400;
    endpoints.dst_port = drivers::kLivoxMid360ImuPort;
    constexpr std::int64_t kCaptureLatencyNs = 100'000;
    std::vector<std::uint8_t> bytes(drivers::kLivoxSdk2ImuPacketBytes);
    for (; livox_imu_written < livox_samples.size(); ++livox_imu_written) {
      const ImuSample& sample = livox_samples[livox_imu_written];
      const std::int64_t stamp_ns = o.start_time_ns + std::llround(sample.stamp * 1e9);
      if (stamp_ns + kCaptureLatencyNs > until_ns) break;
      const float gyro[3] = {static_cast<float>(sample.gyro.x()), static_cast<float>(sample.gyro.y()),
                             static_cast<float>(sample.gyro.z())};
      const float accel_g[3] = {static_cast<float>(sample.accel.x() / kStandardGravity),
                                static_cast<float>(sample.accel.y() / kStandardGravity),
                                static_cast<float>(sample.accel.z() / kStandardGravity)};
      drivers::encode_livox_sdk2_imu(stamp_ns, static_cast<std::uint16_t>(livox_imu_written), gyro, accel_g, bytes);
      pcap.write_udp(stamp_ns + kCaptureLatencyNs, endpoints, bytes);
    }
  };
  if (is_livox(o)) {
    LivoxSimOptions livox;
    livox.effects = lidar.effects;
    livox.seed = o.seed;
    livox.start_time_ns = o.start_time_ns;
    livox.extrinsics = lidar.extrinsics;
    const LivoxSimStats s = simulate_livox_lidar(LivoxPattern{}, body, caster, scene.mesh, targets, people, livox, pcap,
                                                 write_livox_imu_packets);
    write_livox_imu_packets(std::numeric_limits<std::int64_t>::max());
    stats.packets = s.packets;
    stats.rays = s.rays;
    stats.returns = s.returns;
  } else {
    stats = simulate_spinning_lidar(sensor, body, caster, scene.mesh, targets, people, lidar, pcap,
                                    ouster_imu ? std::function<void(std::int64_t)>(write_imu_packets) : nullptr);
  }
  write_imu_packets(std::numeric_limits<std::int64_t>::max());
  pcap.flush();
  if (is_livox(o))
    write_imu_truth(o.out / (imu_source == SimImuSource::livox ? "truth_imu.csv" : "truth_livox_imu.csv"), livox_samples,
                    o.start_time_ns, livox_imu.time_offset_s);

  WheelOptions wheels;
  wheels.radius_error = o.wheel_radius_error;
  wheels.slips_per_minute = o.slips_per_minute;
  wheels.time_offset_s = o.can_offset_s;
  wheels.start_time_ns = o.start_time_ns;
  wheels.seed = o.seed;
  const bool wheels_on = o.wheels && o.platform == "robot";
  const bool can_imu = imu_source == SimImuSource::can;
  const ImuOptions imu = simulated_imu(o, SimImuSource::can);
  if (wheels_on || can_imu) {
    std::vector<drivers::can::Frame> frames;
    if (wheels_on) {
      const WheelTruth truth = simulate_wheel_encoders(body, wheels, frames);
      write_wheel_truth(o.out / "truth_wheels.csv", truth, o.start_time_ns);
    }
    if (can_imu) {
      const std::vector<ImuSample> samples = simulate_imu(body, imu);
      if (samples.empty()) throw InputError("adit sim", "--duration", "too short for one IMU sample");
      ImuFrameOptions f;
      f.start_time_ns = o.start_time_ns;
      append_imu_frames(samples, f, frames);
      write_imu_truth(o.out / "truth_imu.csv", samples, o.start_time_ns, imu.time_offset_s);
      log::info("sim: IMU turn-on bias gyro {:+.5f} {:+.5f} {:+.5f} rad/s, accelerometer {:+.4f} {:+.4f} {:+.4f} m/s²",
                samples.front().gyro_bias.x(), samples.front().gyro_bias.y(), samples.front().gyro_bias.z(),
                samples.front().accel_bias.x(), samples.front().accel_bias.y(), samples.front().accel_bias.z());
    }
    std::stable_sort(frames.begin(), frames.end(), [](const auto& a, const auto& b) { return a.time_us < b.time_us; });
    drivers::can::CandumpWriter writer(o.out / "can.log");
    for (const drivers::can::Frame& f : frames) writer.write(f);
    writer.flush();
  }
  if (ouster_imu)
    write_imu_truth(o.out / (can_imu ? "truth_ouster_imu.csv" : "truth_imu.csv"), ouster_samples, o.start_time_ns,
                    ouster_imu_options.time_offset_s);
  write_tum(o.out / "truth_body.tum", body, Eigen::Isometry3d::Identity(), o.start_time_ns);
  write_tum(o.out / "truth_sensor.tum", body, lidar.extrinsics, o.start_time_ns);
  write_ply(o.out / "scene.ply", scene.mesh);
  if (!scene.design.triangles.empty()) write_ply_points(o.out / "bim.ply", sample_surface(scene.design, 100.0, o.seed));
  write_targets_csv(o.out / "targets.csv", targets);
  if (!people.empty()) write_people_truth(o.out / "truth_people.csv", people, o.duration_s, 0.05, o.start_time_ns);
  write_session_config(o.out / "session.yaml", o, is_livox(o) ? std::string() : sensor.calibration_file, wheels,
                       simulated_imu(o, imu_source == SimImuSource::none ? SimImuSource::can : imu_source), imu_source,
                       lidar.extrinsics);

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
