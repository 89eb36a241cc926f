// adit sim: generate a simulated survey session (packets, CAN log, ground truth).

#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/sim/session.hpp"
#include "commands.hpp"

namespace adit::tools {

void register_sim_commands(CLI::App& app, int& status) {
  auto o = std::make_shared<sim::SimOptions>();
  auto out = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "sim", "Simulate a survey session: lidar.pcap, can.log, session.yaml and ground truth in --out");
  cmd->add_option("--scene", o->scene, "Scene: mine (drift loop, junctions, stope), drift (straight, featureless 200 m) or building (office floor; writes bim.ply)")
      ->capture_default_str();
  cmd->add_option("--platform", o->platform,
                  "Platform: robot (differential drive, wheel encoders on CAN), drone (6-DoF multirotor) or handheld "
                  "(a person walking with the scanner)")
      ->capture_default_str();
  cmd->add_option("--sensor", o->sensor, "LiDAR model: VLP-16, RS-16, PandarXT32, OS1-64 (1024x10, LEGACY profile, 600 rpm) or Mid-360 (Livox SDK2 points and IMU, a non-repetitive pattern model)")->capture_default_str();
  cmd->add_option("--duration", o->duration_s, "Session length, seconds")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed: the same seed and options give byte-identical files")->capture_default_str();
  cmd->add_option("--out", *out, "Output folder (created)")->required();
  cmd->add_option("--noise-m", o->noise_m, "Range noise σ, metres")->capture_default_str();
  cmd->add_option("--dropout", o->dropout, "Probability that a return is lost")->capture_default_str();
  cmd->add_option("--min-range-m", o->min_range_m, "Closest return the sensor reports, metres")->capture_default_str();
  cmd->add_option("--max-range-m", o->max_range_m, "Farthest return the sensor reports, metres")->capture_default_str();
  cmd->add_option("--rpm", o->rpm, "LiDAR head rotation, rpm")->capture_default_str();
  cmd->add_option("--speed", o->speed_mps,
                  "Cruise speed, m/s (robot at most 1.5, drone 2, handheld 1.5); 0: the platform's own (1.0, 1.0, 1.3)")
      ->capture_default_str();
  cmd->add_option("--lateral-offset-m", o->lateral_offset_m, "Drive this far left (+) of the drift's centre line")
      ->capture_default_str();
  cmd->add_option("--ground-s", o->ground_s,
                  "Drone: seconds on the floor with the rotors running before the take-off")
      ->capture_default_str();
  cmd->add_option("--wheel-radius-error", o->wheel_radius_error,
                  "True wheel radius relative error against the configured one")
      ->capture_default_str();
  cmd->add_option("--slips-per-minute", o->slips_per_minute, "Wheel slip events per minute")->capture_default_str();
  cmd->add_option("--can-offset-s", o->can_offset_s, "CAN clock minus LiDAR clock, seconds")->capture_default_str();
  cmd->add_option("--imu", o->imu,
                  "An IMU: on CAN (robot; drone and handheld with a LiDAR without one: accelerometer 0x190, gyroscope "
                  "0x191) or the LiDAR's own (OS1-64: IMU packets to port 7503; Mid-360: to 56401)")
      ->capture_default_str();
  cmd->add_flag("--imu-on-can", o->imu_on_can,
                "Read a CAN IMU even where the LiDAR has its own (drone, handheld), to compare the two");
  cmd->add_option("--imu-rate-hz", o->imu_rate_hz, "IMU samples per second, 100-400 (0: 200 on CAN, 100 from an Ouster)")
      ->capture_default_str();
  cmd->add_option("--gyro-noise-density", o->imu_noise.gyro_noise_density, "Gyroscope white noise, rad/s/√Hz")
      ->capture_default_str();
  cmd->add_option("--accel-noise-density", o->imu_noise.accel_noise_density, "Accelerometer white noise, m/s²/√Hz")
      ->capture_default_str();
  cmd->add_option("--gyro-bias-walk", o->imu_noise.gyro_bias_walk, "Gyroscope bias random walk, rad/s²/√Hz")
      ->capture_default_str();
  cmd->add_option("--accel-bias-walk", o->imu_noise.accel_bias_walk, "Accelerometer bias random walk, m/s³/√Hz")
      ->capture_default_str();
  cmd->add_option("--gyro-bias-sigma", o->imu_noise.gyro_turn_on_sigma, "σ of the gyroscope's turn-on bias per axis, rad/s")
      ->capture_default_str();
  cmd->add_option("--imu-bias-mps2", o->imu_noise.accel_turn_on_sigma,
                  "σ of the accelerometer's turn-on bias per axis, m/s²")
      ->capture_default_str();
  cmd->add_option_function<std::vector<double>>(
         "--mount-rpy-deg", [o](const std::vector<double>& v) { o->mount_rpy_deg = Eigen::Vector3d(v[0], v[1], v[2]); },
         "The LiDAR's mounting rotation on the platform: roll pitch yaw, degrees, applied Z·Y·X (default 0 0 0)")
      ->expected(3);
  cmd->add_option_function<std::vector<double>>(
         "--imu-position-m", [o](const std::vector<double>& v) { o->imu_position_m = Eigen::Vector3d(v[0], v[1], v[2]); },
         "A CAN IMU's origin in the body frame x y z, metres (the lever arm; default 0 0 0)")
      ->expected(3);
  cmd->add_option("--imu-time-offset-s", o->imu_time_offset_s,
                  "The IMU's stamps minus the true time, seconds (a CAN IMU's on top of --can-offset-s)")
      ->capture_default_str();
  cmd->add_option("--vibration", o->vibration, "Rotor vibration in the IMU: auto (the drone's), on or off")
      ->capture_default_str();
  cmd->add_option("--targets", o->targets, "Surveyed wall targets to place")->capture_default_str();
  cmd->add_option("--people", o->people, "People walking along the route (moving obstacles, not in scene.ply)")
      ->capture_default_str();
  cmd->add_option("--threads", o->threads, "Ray-casting threads (outputs do not depend on it)")->capture_default_str();
  cmd->callback([o, out, &status] {
    o->out = *out;
    const sim::SimSummary s = sim::run_simulation(*o);
    fmt::print("{}: {} packets, {} returns, path {:.1f} m, {} targets, scene {} triangles\n", *out, s.packets,
               s.returns, s.path_length_m, s.targets, s.triangles);
    status = kExitOk;
  });
}

}  // namespace adit::tools
