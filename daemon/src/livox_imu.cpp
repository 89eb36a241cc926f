// A Livox IMU's packets into body-frame readings on the LiDAR clock
// (livox_imu.hpp). push() runs per packet on the assembly thread.
#include "adit/daemon/livox_imu.hpp"

#include <array>

#include "adit/daemon/extrinsics.hpp"
#include "adit/drivers/lidar/livox_packet.hpp"

namespace adit::daemon {

ImuMounting livox_imu_mounting(drivers::LivoxModel model, const config::Transform& lidar_extrinsics) {
  const Eigen::Isometry3d body_from_sensor = isometry_of(lidar_extrinsics);
  const std::array<double, 3> in_sensor = drivers::livox_imu_position_m(model);
  ImuMounting out;
  out.rotation = body_from_sensor.linear();
  out.position_m = body_from_sensor * Eigen::Vector3d(in_sensor[0], in_sensor[1], in_sensor[2]);
  return out;
}

LivoxImu::LivoxImu(const config::Config& config, const ImuMounting& mounting, bool replay)
    : PacketImu(config, mounting, replay) {}

void LivoxImu::push(std::span<const std::uint8_t> payload, std::int64_t /*host_time_ns*/,
                    std::int64_t received_mono_ns, const drivers::ClockOffsetEstimator& lidar_clock) {
  const std::uint64_t n = count_packet();
  const std::optional<drivers::LivoxImuReading> raw = drivers::decode_livox_imu(payload);
  if (!raw) {
    monitor_.report(ImuProblem::undecodable, n);
    return;
  }
  const std::optional<drivers::ClockEstimate> lidar = lidar_clock.estimate();
  if (!lidar || !near_lidar(*lidar, raw->sensor_time_ns)) {
    monitor_.report(ImuProblem::unclocked, n);
    return;
  }
  hand_on(Eigen::Vector3d(raw->accel_m_s2[0], raw->accel_m_s2[1], raw->accel_m_s2[2]),
          Eigen::Vector3d(raw->gyro_rad_s[0], raw->gyro_rad_s[1], raw->gyro_rad_s[2]), raw->sensor_time_ns,
          lidar_clock, n, received_mono_ns);
}

}  // namespace adit::daemon
