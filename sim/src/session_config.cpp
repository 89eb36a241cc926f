#include "adit/sim/session_config.hpp"

#include <cmath>
#include <fstream>
#include <numbers>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/sim/imu_frames.hpp"
#include "adit/slam/roll_pitch_yaw.hpp"

namespace adit::sim {

namespace {

// Roll, pitch, yaw in degrees as the config reads them.
Eigen::Vector3d rpy_deg(const Eigen::Matrix3d& r) { return slam::rpy_of(r) * (180.0 / std::numbers::pi); }

}  // namespace

void write_session_config(const std::filesystem::path& file, const SimOptions& o,
                          const std::string& calibration_file, const WheelOptions& w, const ImuOptions& imu,
                          SimImuSource imu_source, const Eigen::Isometry3d& extrinsics) {
  const Eigen::Vector3d t = extrinsics.translation();
  const Eigen::Vector3d rpy = rpy_deg(extrinsics.linear());
  std::string text = fmt::format(
      "# A simulated session (adit sim --scene {} --platform {} --sensor {} --duration {} --seed {}).\n"
      "# Replays lidar.pcap and can.log; ground truth is in truth_*.tum, truth_imu.csv, scene.ply, targets.csv.\n"
      "payload:\n  id: sim-{}-{}\n  state_dir: state\n\n"
      "log:\n  level: info\n\n"
      "lidar:\n  model: {}\n  source: pcap\n  pcap: lidar.pcap\n{}  replay_speed: 1.0\n"
      "  return_mode: strongest\n  min_range_m: {}\n  max_range_m: {}\n"
      "  extrinsics:\n    xyz_m: [{}, {}, {}]\n    rpy_deg: [{:.9g}, {:.9g}, {:.9g}]\n\n",
      o.scene, o.platform, o.sensor, o.duration_s, o.seed, o.scene, o.seed, o.sensor,
      calibration_file.empty() ? std::string() : "  calibration: " + calibration_file + "\n", o.min_range_m, o.max_range_m,
      t.x(), t.y(), t.z(), rpy.x() + 0.0, rpy.y() + 0.0, rpy.z() + 0.0);  // + 0.0: no "-0"
  const bool wheels = o.wheels && o.platform == "robot";
  const bool can_imu = imu_source == SimImuSource::can;
  if (wheels || can_imu) {
    // The IMU shares the wheels' bus (sim/imu_frames.hpp: accelerometer 0x190, gyroscope 0x191).
    std::string signals;
    if (wheels)
      signals += fmt::format(
          "    - {{name: left_wheel_position, id: {:#x}, start_bit: 0, length: 32, byte_order: intel, value_type: signed, unit: counts}}\n"
          "    - {{name: right_wheel_position, id: {:#x}, start_bit: 0, length: 32, byte_order: intel, value_type: signed, unit: counts}}\n",
          w.left_id, w.right_id);
    const ImuFrameOptions frames;
    if (can_imu) {
      for (int axis = 0; axis < 3; ++axis)
        signals += fmt::format("    - {{name: imu_accel_{}, id: {:#x}, start_bit: {}, length: 16, byte_order: intel, "
                               "value_type: signed, factor: {}, unit: m/s2}}\n",
                               "xyz"[axis], frames.accel_id, 16 * axis, frames.accel_lsb);
      for (int axis = 0; axis < 3; ++axis)
        signals += fmt::format("    - {{name: imu_gyro_{}, id: {:#x}, start_bit: {}, length: 16, byte_order: intel, "
                               "value_type: signed, factor: {}, unit: rad/s}}\n",
                               "xyz"[axis], frames.gyro_id, 16 * axis, frames.gyro_lsb);
    }
    text += fmt::format("can:\n  enabled: true\n  source: candump\n  log: can.log\n  signals:\n{}\n", signals);
  }
  if (wheels) {
    text += fmt::format(
        "wheel_odometry:\n  enabled: true\n  model: differential\n  left_signal: left_wheel_position\n"
        "  right_signal: right_wheel_position\n  quantity: counts\n  counts_per_revolution: {}\n  counter_bits: 32\n"
        "  left_radius_m: {}\n  right_radius_m: {}\n  track_width_m: {}\n  time_offset_s: {}\n"
        "  max_acceleration_mps2: 4.0  # the robot's traction: a wheel speeding up faster slips\n\n",
        w.counts_per_revolution, w.radius_m, w.radius_m, w.track_m, o.can_offset_s + 0.0);
  } else if (can_imu) {
    text += "wheel_odometry:\n  enabled: false\n\n";
  }
  if (imu_source != SimImuSource::none) {
    const Eigen::Vector3d p = imu.mount.translation();
    const Eigen::Vector3d r = rpy_deg(imu.mount.linear());
    text += fmt::format("imu:\n  enabled: true\n  source: {}\n",
                        can_imu ? "can" : imu_source == SimImuSource::ouster ? "ouster" : "livox");
    if (can_imu)
      text += "  accel_x_signal: imu_accel_x\n  accel_y_signal: imu_accel_y\n  accel_z_signal: imu_accel_z\n"
              "  gyro_x_signal: imu_gyro_x\n  gyro_y_signal: imu_gyro_y\n  gyro_z_signal: imu_gyro_z\n";
    // The noise model as simulated (truth_imu.csv has the biases it drew).
    text += fmt::format(
        "  rpy_deg: [{}, {}, {}]\n  position_m: [{}, {}, {}]\n  time_offset_s: {}\n"
        "  gyro_noise_density: {}\n  accel_noise_density: {}\n  gyro_bias_walk: {}\n  accel_bias_walk: {}\n\n",
        r.x() + 0.0, r.y() + 0.0, r.z() + 0.0, p.x() + 0.0, p.y() + 0.0, p.z() + 0.0, imu.time_offset_s + 0.0,
        o.imu_noise.gyro_noise_density, o.imu_noise.accel_noise_density, o.imu_noise.gyro_bias_walk,
        o.imu_noise.accel_bias_walk);
  }
  text += "lcm:\n  url: udpm://239.255.76.67:7667?ttl=0\n";
  std::ofstream out(file, std::ios::trunc);
  out << text;
  if (!out) throw InputError(file.string(), "", "could not write the session config");
}

}  // namespace adit::sim
