// A Livox IMU's packets into body-frame readings on the LiDAR clock
// (livox_imu.hpp). push() runs per packet on the assembly thread.
#include "adit/daemon/livox_imu.hpp"

#include <cmath>

#include "adit/common/clock.hpp"
#include "adit/daemon/extrinsics.hpp"
#include "adit/drivers/lidar/livox_packet.hpp"

namespace adit::daemon {

ImuMounting livox_mid360_imu_mounting(const config::Transform& lidar_extrinsics) {
  const Eigen::Isometry3d body_from_sensor = isometry_of(lidar_extrinsics);
  ImuMounting out;
  out.rotation = body_from_sensor.linear();
  out.position_m = body_from_sensor * Eigen::Vector3d(0.011, 0.02329, -0.04412);
  return out;
}

LivoxImu::LivoxImu(const config::Config& config, const ImuMounting& mounting, bool replay)
    : mounting_(mounting),
      monitor_(stats_, ImuLimits{config.imu.accel_range_mps2, config.imu.gyro_range_radps}),
      replay_(replay),
      time_offset_s_(config.imu.time_offset_s),
      readings_(1024, Overflow::drop_oldest, [] { return slam::ImuSample{}; }) {
  stats_.time_offset_s.store(time_offset_s_);
}

void LivoxImu::push(std::span<const std::uint8_t> payload, std::int64_t /*host_time_ns*/,
                    const drivers::ClockOffsetEstimator& lidar_clock) {
  const std::uint64_t n = ++packets_;
  stats_.packets.store(n, std::memory_order_relaxed);
  const std::optional<drivers::LivoxImuReading> raw = drivers::decode_livox_imu(payload);
  if (!raw) {
    monitor_.report(ImuProblem::undecodable, n);
    return;
  }
  const std::optional<drivers::ClockEstimate> lidar = lidar_clock.estimate();
  if (!lidar || std::abs(static_cast<double>(raw->sensor_time_ns) - static_cast<double>(lidar->at_sensor_ns)) >
                    kMaxFromLidarNs) {
    monitor_.report(ImuProblem::unclocked, n);
    return;
  }
  slam::ImuSample r;
  r.t = 1e-9 * static_cast<double>(lidar_clock.to_host(raw->sensor_time_ns)) - time_offset_s_;
  r.specific_force = Eigen::Vector3d(raw->accel_m_s2[0], raw->accel_m_s2[1], raw->accel_m_s2[2]);
  r.angular_rate = Eigen::Vector3d(raw->gyro_rad_s[0], raw->gyro_rad_s[1], raw->gyro_rad_s[2]);
  r.has_gyro = true;
  if (!monitor_.check(r, n)) return;
  r.specific_force = mounting_.rotation * r.specific_force;
  r.angular_rate = mounting_.rotation * r.angular_rate;
  slam::ImuSample* out = readings_.acquire();  // never waits: drops the oldest
  if (out == nullptr) return;
  *out = r;
  readings_.publish(out);
  stats_.samples.fetch_add(1, std::memory_order_relaxed);
  stats_.gyro_samples.fetch_add(1, std::memory_order_relaxed);
  stats_.dropped.store(readings_.dropped(), std::memory_order_relaxed);
  stats_.last_seen_realtime_ns.store(realtime_ns(), std::memory_order_relaxed);
}

void LivoxImu::catch_up(double until_t, const std::function<bool()>& idle) {
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
