#pragma once
// One simulated survey session: options in, a folder of files out, laid out
// like a field recording plus its ground truth:
//   lidar.pcap        the sensor's UDP packets (and an Ouster's IMU packets, port 7503; a Mid-360's, 56401)
//   can.log           wheel TPDOs and the CAN IMU's frames (candump -L)
//   truth_imu.csv     the IMU's true biases per sample, the IMU session.yaml reads (truth_ouster_imu.csv,
//                     truth_livox_imu.csv: the LiDAR's own when the CAN IMU is read beside it)
//   VLP16.yaml, RS16.csv, PandarXT32.csv or OS1-64.json (metadata): the calibration
//   session.yaml      an adit config that replays it
//   truth_body.tum    body trajectory (TUM)          truth_sensor.tum sensor trajectory (TUM)
//   truth_wheels.csv  wheel angles per CAN frame     scene.ply        the surfaces (binary PLY mesh)
//   targets.csv       surveyed wall targets (id,x,y,z)

#include <cstdint>
#include <filesystem>
#include <string>

#include <Eigen/Geometry>

#include "adit/sim/people.hpp"
#include "adit/sim/scene.hpp"
#include "adit/sim/body_track.hpp"
#include "adit/sim/imu.hpp"

namespace adit::sim {

struct SimOptions {
  std::string scene = "mine";      // mine | drift
  std::string platform = "robot";  // robot | drone | handheld (no wheels: their can.log has only the IMU's frames)
  std::string sensor = "VLP-16";   // VLP-16 | RS-16 | PandarXT32 | OS1-64
  double duration_s = 60.0;
  std::uint64_t seed = 1;
  std::filesystem::path out;
  // Sensor
  double noise_m = 0.02;
  double dropout = 0.002;
  double min_range_m = 0.5;
  double max_range_m = 100.0;
  double rpm = 600.0;
  // Platform and path
  double speed_mps = 0.0;  // 0: the platform's own pace (robot, drone 1.0 m/s; handheld 1.3 m/s)
  double lateral_offset_m = 0.0;
  double ground_s = 0.0;  // drone: s on the floor, rotors running, before the take-off
  // The LiDAR's mounting rotation on the platform (roll, pitch, yaw in
  // degrees, the config's Z·Y·X): a sensor tilted or turned on its bracket.
  Eigen::Vector3d mount_rpy_deg = Eigen::Vector3d::Zero();
  // Wheels
  bool wheels = true;
  double wheel_radius_error = 0.004;
  double slips_per_minute = 1.0;
  double can_offset_s = 0.0;  // CAN clock minus LiDAR clock
  // The IMU (sim/imu.hpp): on the CAN bus (robots; drones and handhelds with
  // a LiDAR without one), or the LiDAR's own (Ouster, Mid-360), in its packets.
  bool imu = true;
  bool imu_on_can = false;  // the CAN IMU even when the LiDAR has its own (which still sends its packets)
  double imu_rate_hz = 0.0;  // 0: 200 Hz on CAN, 100 Hz from an Ouster (what the real sensor sends)
  ImuNoise imu_noise;        // densities, walks and turn-on biases (the accelerometer's: --imu-bias-mps2)
  Eigen::Vector3d imu_position_m = Eigen::Vector3d::Zero();  // the CAN IMU in the body frame (lever arm)
  double imu_time_offset_s = 0.0;  // the IMU's stamps minus the true time, on top of --can-offset-s for CAN
  std::string vibration = "auto";  // rotor vibration: auto (the drone's), on, off
  int targets = 8;
  int people = 0;  // walkers along the route (dynamic objects)
  std::int64_t start_time_ns = 1'767'225'600'000'000'000;  // 2026-01-01T00:00:00Z
  int threads = 2;
};

struct SimSummary {
  std::uint64_t packets = 0;
  std::uint64_t returns = 0;
  std::size_t triangles = 0;
  std::size_t targets = 0;
  double path_length_m = 0.0;
};

// The scene and the body trajectory run_simulation uses (deterministic), for checks.
Scene simulated_scene(const SimOptions& options);
BodyTrack simulated_path(const Scene& scene, const SimOptions& options);
Eigen::Isometry3d simulated_extrinsics(const SimOptions& options);  // sensor in the body frame

// Which IMU session.yaml reads (none with --imu 0).
enum class SimImuSource { none, can, ouster, livox };
SimImuSource simulated_imu_source(const SimOptions& options);
// The IMU simulated for that source (can, ouster or livox): rate, noise, mount, clock, motion model, seed.
ImuOptions simulated_imu(const SimOptions& options, SimImuSource source);
double platform_speed_mps(const SimOptions& options);  // --speed, or the platform's own pace
People simulated_people(const Scene& scene, const SimOptions& options);  // the scene must outlive them

// Throws adit::InputError (key = the option) for impossible options, before any work.
void validate(const SimOptions& options);
// Validates, builds the scene and path (throws adit::InputError when the path
// leaves the scene, before writing anything), then writes the session.
SimSummary run_simulation(const SimOptions& options);

}  // namespace adit::sim
