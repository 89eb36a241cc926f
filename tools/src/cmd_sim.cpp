// adit sim: generate a simulated survey session (packets, CAN log, ground truth).

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
  cmd->add_option("--platform", o->platform, "Platform: robot (differential drive, wheel encoders on CAN) or drone (6-DoF multirotor)")->capture_default_str();
  cmd->add_option("--sensor", o->sensor, "LiDAR model: VLP-16, RS-16, PandarXT32 or OS1-64 (1024x10, LEGACY profile, 600 rpm)")->capture_default_str();
  cmd->add_option("--duration", o->duration_s, "Session length, seconds")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed: the same seed and options give byte-identical files")->capture_default_str();
  cmd->add_option("--out", *out, "Output folder (created)")->required();
  cmd->add_option("--noise-m", o->noise_m, "Range noise σ, metres")->capture_default_str();
  cmd->add_option("--dropout", o->dropout, "Probability that a return is lost")->capture_default_str();
  cmd->add_option("--min-range-m", o->min_range_m, "Closest return the sensor reports, metres")->capture_default_str();
  cmd->add_option("--max-range-m", o->max_range_m, "Farthest return the sensor reports, metres")->capture_default_str();
  cmd->add_option("--rpm", o->rpm, "LiDAR head rotation, rpm")->capture_default_str();
  cmd->add_option("--speed", o->speed_mps, "Cruise speed, m/s (robot at most 1.5, drone 2)")->capture_default_str();
  cmd->add_option("--lateral-offset-m", o->lateral_offset_m, "Drive this far left (+) of the drift's centre line")
      ->capture_default_str();
  cmd->add_option("--wheel-radius-error", o->wheel_radius_error,
                  "True wheel radius relative error against the configured one")
      ->capture_default_str();
  cmd->add_option("--slips-per-minute", o->slips_per_minute, "Wheel slip events per minute")->capture_default_str();
  cmd->add_option("--can-offset-s", o->can_offset_s, "CAN clock minus LiDAR clock, seconds")->capture_default_str();
  cmd->add_option("--imu", o->imu, "Robot: an accelerometer on the CAN bus (0x190, m/s² × 1000 in three int16)")
      ->capture_default_str();
  cmd->add_option("--imu-bias-mps2", o->imu_bias_sigma_mps2, "σ of the accelerometer's constant bias per axis, m/s²")
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
