#include "adit/sim/session_config.hpp"

#include <cmath>
#include <fstream>
#include <numbers>

#include <fmt/format.h>

#include "adit/common/error.hpp"

namespace adit::sim {

void write_session_config(const std::filesystem::path& file, const SimOptions& o,
                          const std::string& calibration_file, const WheelOptions& w, const ImuOptions& imu,
                          const Eigen::Isometry3d& extrinsics) {
  const Eigen::Vector3d t = extrinsics.translation();
  const Eigen::Vector3d rpy = Eigen::Vector3d(Eigen::Matrix3d(extrinsics.linear()).eulerAngles(2, 1, 0).reverse()) * 180.0 / std::numbers::pi;
  std::string text = fmt::format(
      "# A simulated session (adit sim --scene {} --platform {} --sensor {} --duration {} --seed {}).\n"
      "# Replays lidar.pcap and can.log; ground truth is in truth_*.tum, scene.ply, targets.csv.\n"
      "payload:\n  id: sim-{}-{}\n  state_dir: state\n\n"
      "log:\n  level: info\n\n"
      "lidar:\n  model: {}\n  source: pcap\n  pcap: lidar.pcap\n  calibration: {}\n  replay_speed: 1.0\n"
      "  return_mode: strongest\n  min_range_m: {}\n  max_range_m: {}\n"
      "  extrinsics:\n    xyz_m: [{}, {}, {}]\n    rpy_deg: [{}, {}, {}]\n\n",
      o.scene, o.platform, o.sensor, o.duration_s, o.seed, o.scene, o.seed, o.sensor, calibration_file, o.min_range_m, o.max_range_m,
      t.x(), t.y(), t.z(), rpy.x() + 0.0, rpy.y() + 0.0, rpy.z() + 0.0);  // + 0.0: no "-0"
  if (o.wheels && o.platform == "robot") {
    // The accelerometer shares the wheels' bus (sim/imu.hpp).
    std::string imu_signals;
    if (o.imu)
      for (int axis = 0; axis < 3; ++axis)
        imu_signals += fmt::format("    - {{name: imu_accel_{}, id: {:#x}, start_bit: {}, length: 16, byte_order: intel, "
                                   "value_type: signed, factor: {}, unit: m/s2}}\n",
                                   "xyz"[axis], imu.id, 16 * axis, imu.lsb_mps2);
    text += fmt::format(
        "can:\n  enabled: true\n  source: candump\n  log: can.log\n  signals:\n"
        "    - {{name: left_wheel_position, id: {:#x}, start_bit: 0, length: 32, byte_order: intel, value_type: signed, unit: counts}}\n"
        "    - {{name: right_wheel_position, id: {:#x}, start_bit: 0, length: 32, byte_order: intel, value_type: signed, unit: counts}}\n"
        "{}\n"
        "wheel_odometry:\n  enabled: true\n  model: differential\n  left_signal: left_wheel_position\n"
        "  right_signal: right_wheel_position\n  quantity: counts\n  counts_per_revolution: {}\n  counter_bits: 32\n"
        "  left_radius_m: {}\n  right_radius_m: {}\n  track_width_m: {}\n  time_offset_s: {}\n"
        "  max_acceleration_mps2: 4.0  # the robot's traction: a wheel speeding up faster slips\n\n",
        w.left_id, w.right_id, imu_signals, w.counts_per_revolution, w.radius_m, w.radius_m, w.track_m,
        0.0 - o.can_offset_s);
    if (o.imu)
      text += fmt::format(
          "imu:\n  enabled: true\n  accel_x_signal: imu_accel_x\n  accel_y_signal: imu_accel_y\n  accel_z_signal: imu_accel_z\n"
          "  rpy_deg: [0, 0, 0]\n  time_offset_s: {}\n\n",
          0.0 - o.can_offset_s);
  }
  text += "lcm:\n  url: udpm://239.255.76.67:7667?ttl=0\n";
  std::ofstream out(file, std::ios::trunc);
  out << text;
  if (!out) throw InputError(file.string(), "", "could not write the session config");
}

}  // namespace adit::sim
