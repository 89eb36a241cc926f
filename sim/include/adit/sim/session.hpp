#pragma once
// One simulated survey session: options in, a folder of files out, laid out
// like a field recording plus its ground truth:
//   lidar.pcap        the sensor's UDP packets       can.log          wheel TPDOs and accelerometer (candump -L)
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

namespace adit::sim {

struct SimOptions {
  std::string scene = "mine";      // mine | drift
  std::string platform = "robot";  // robot | drone (no wheels, no can.log)
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
  double speed_mps = 1.0;
  double lateral_offset_m = 0.0;
  // Wheels
  bool wheels = true;
  double wheel_radius_error = 0.004;
  double slips_per_minute = 1.0;
  double can_offset_s = 0.0;  // CAN clock minus LiDAR clock
  // The robot's accelerometer on the same bus (sim/imu.hpp); its bias σ per axis.
  bool imu = true;
  double imu_bias_sigma_mps2 = 0.0098;
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
People simulated_people(const Scene& scene, const SimOptions& options);  // the scene must outlive them

// Throws adit::InputError (key = the option) for impossible options, before any work.
void validate(const SimOptions& options);
// Validates, builds the scene and path (throws adit::InputError when the path
// leaves the scene, before writing anything), then writes the session.
SimSummary run_simulation(const SimOptions& options);

}  // namespace adit::sim
