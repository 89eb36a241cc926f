// The Ouster IMU's packets into body-frame readings on the LiDAR clock
// (ouster_imu.hpp). push() runs per packet on the assembly thread: no
// allocation, lock or log there.
#include "adit/daemon/ouster_imu.hpp"

#include <Eigen/Geometry>

#include "adit/common/error.hpp"
#include "adit/daemon/extrinsics.hpp"
#include "adit/drivers/lidar/ouster_packet.hpp"

namespace adit::daemon {

ImuMounting ouster_imu_mounting(const drivers::OusterMetadata& m, const config::Transform& lidar_extrinsics,
                                const std::string& metadata_file) {
  const auto& T = m.imu_to_sensor;
  Eigen::Matrix3d rotation;
  rotation << T[0], T[1], T[2], T[4], T[5], T[6], T[8], T[9], T[10];
  if (!rotation.allFinite() || (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm() > 1e-3 ||
      rotation.determinant() < 0.0)
    throw InputError(metadata_file, "imu_to_sensor_transform", "its 3×3 part is not a rotation");
  const Eigen::Vector3d translation_m = 1e-3 * Eigen::Vector3d(T[3], T[7], T[11]);
  const Eigen::Isometry3d body_from_sensor = isometry_of(lidar_extrinsics);
  ImuMounting out;
  out.rotation = body_from_sensor.linear() * rotation;
  out.position_m = body_from_sensor * translation_m;
  return out;
}

OusterImu::OusterImu(const config::Config& config, const drivers::OusterMetadata& metadata, bool replay)
    : PacketImu(config, ouster_imu_mounting(metadata, config.lidar.extrinsics, config.lidar.calibration), replay),
      port_(metadata.udp_port_imu) {
  if (metadata.imu_profile != "LEGACY")
    throw InputError(config.lidar.calibration, "udp_profile_imu",
                     "imu.source ouster reads the LEGACY IMU profile (48-byte packets), not " + metadata.imu_profile);
}

void OusterImu::push(std::span<const std::uint8_t> payload, std::int64_t host_time_ns, std::int64_t received_mono_ns,
                     const drivers::ClockOffsetEstimator& lidar_clock) {
  const std::uint64_t n = count_packet();
  drivers::OusterImuSample raw;
  if (!drivers::decode_ouster_imu(payload, raw)) {
    monitor_.report(ImuProblem::undecodable, n);
    return;
  }
  const auto accel_time_ns = static_cast<std::int64_t>(raw.accel_time_ns);
  const std::optional<drivers::ClockEstimate> lidar = lidar_clock.estimate();
  if (!lidar || !near_lidar(*lidar, accel_time_ns)) {
    monitor_.report(ImuProblem::unclocked, n);
    return;
  }
  const auto system_time_ns = static_cast<std::int64_t>(raw.system_time_ns);
  if (host_time_ns > 0 && near_lidar(*lidar, system_time_ns)) {
    packet_clock_.add(system_time_ns, host_time_ns);
    if (const std::optional<drivers::ClockEstimate> own = packet_clock_.estimate())
      stats_.clock_spread_s.store(1e-9 * (static_cast<double>(own->offset_ns) - static_cast<double>(lidar->offset_ns)),
                                  std::memory_order_relaxed);
  }
  hand_on(Eigen::Vector3d(raw.accel_mps2[0], raw.accel_mps2[1], raw.accel_mps2[2]),
          Eigen::Vector3d(raw.gyro_radps[0], raw.gyro_radps[1], raw.gyro_radps[2]), accel_time_ns, lidar_clock, n,
          received_mono_ns);
}

}  // namespace adit::daemon
