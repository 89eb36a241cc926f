// The Ouster IMU's packets into body-frame readings on the LiDAR clock
// (ouster_imu.hpp). push() runs per packet on the assembly thread: no
// allocation, lock or log there.
#include "adit/daemon/ouster_imu.hpp"

#include <cmath>

#include <Eigen/Geometry>

#include "adit/common/clock.hpp"
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
    : mounting_(ouster_imu_mounting(metadata, config.lidar.extrinsics, config.lidar.calibration)),
      monitor_(stats_, ImuLimits{config.imu.accel_range_mps2, config.imu.gyro_range_radps}),
      port_(metadata.udp_port_imu),
      replay_(replay),
      time_offset_s_(config.imu.time_offset_s),
      readings_(1024, Overflow::drop_oldest, [] { return slam::ImuSample{}; }) {
  if (metadata.imu_profile != "LEGACY")
    throw InputError(config.lidar.calibration, "udp_profile_imu",
                     "imu.source ouster reads the LEGACY IMU profile (48-byte packets), not " + metadata.imu_profile);
  stats_.time_offset_s.store(time_offset_s_);
}

void OusterImu::push(std::span<const std::uint8_t> payload, std::int64_t host_time_ns,
                     const drivers::ClockOffsetEstimator& lidar_clock) {
  const std::uint64_t n = ++packets_;
  stats_.packets.store(n, std::memory_order_relaxed);
  drivers::OusterImuSample raw;
  if (!drivers::decode_ouster_imu(payload, raw)) {
    monitor_.report(ImuProblem::undecodable, n);
    return;
  }
  const std::optional<drivers::ClockEstimate> lidar = lidar_clock.estimate();
  // A stamp far from the LiDAR's newest sensor time cannot be put on its
  // clock (nor added to it without overflowing): a corrupt packet.
  const auto near_lidar = [&](std::uint64_t sensor_ns) {
    return std::abs(static_cast<double>(sensor_ns) - static_cast<double>(lidar->at_sensor_ns)) <= kMaxFromLidarNs;
  };
  if (!lidar || !near_lidar(raw.accel_time_ns)) {
    monitor_.report(ImuProblem::unclocked, n);
    return;
  }
  if (host_time_ns > 0 && near_lidar(raw.system_time_ns)) {
    packet_clock_.add(static_cast<std::int64_t>(raw.system_time_ns), host_time_ns);
    if (const std::optional<drivers::ClockEstimate> own = packet_clock_.estimate())
      stats_.clock_spread_s.store(1e-9 * (static_cast<double>(own->offset_ns) - static_cast<double>(lidar->offset_ns)),
                                  std::memory_order_relaxed);
  }
  slam::ImuSample r;
  r.t = 1e-9 * static_cast<double>(lidar_clock.to_host(static_cast<std::int64_t>(raw.accel_time_ns))) - time_offset_s_;
  r.specific_force = Eigen::Vector3d(raw.accel_mps2[0], raw.accel_mps2[1], raw.accel_mps2[2]);
  r.angular_rate = Eigen::Vector3d(raw.gyro_radps[0], raw.gyro_radps[1], raw.gyro_radps[2]);
  r.has_gyro = true;
  if (!monitor_.check(r, n)) return;
  r.specific_force = mounting_.rotation * r.specific_force;
  r.angular_rate = mounting_.rotation * r.angular_rate;
  slam::ImuSample* out = readings_.acquire();  // never waits (header)
  if (out == nullptr) return;
  *out = r;
  readings_.publish(out);
  stats_.samples.fetch_add(1, std::memory_order_relaxed);
  stats_.gyro_samples.fetch_add(1, std::memory_order_relaxed);
  stats_.dropped.store(readings_.dropped(), std::memory_order_relaxed);
  stats_.last_seen_realtime_ns.store(realtime_ns(), std::memory_order_relaxed);
}

void OusterImu::catch_up(double until_t, const std::function<bool()>& idle) {
  // Live: what has arrived. A replay: until the readings or the LiDAR pass
  // until_t, or the source ends.
  const auto covered = [&] {
    return history_.latest() >= until_t || lidar_t_.load(std::memory_order_acquire) >= until_t + 0.1 ||
           readings_.drained();
  };
  const bool wait = replay_ && idle;
  for (;;) {
    slam::ImuSample* s = wait ? readings_.take_or_wait([&] { return !covered() && idle(); }) : readings_.take();
    if (s == nullptr) return;
    history_.push(*s);
    readings_.release(s);
  }
}

}  // namespace adit::daemon
