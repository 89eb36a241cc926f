// A LiDAR's own IMU readings from its decoder to the odometry thread
// (packet_imu.hpp). Everything but catch_up runs per packet on the assembly
// thread: no allocation, lock or log there.
#include "adit/daemon/packet_imu.hpp"

#include <cmath>

#include "adit/common/clock.hpp"
#include "adit/daemon/imu_pose_feed.hpp"

namespace adit::daemon {

PacketImu::PacketImu(const config::Config& config, const ImuMounting& mounting, bool replay)
    : monitor_(stats_, ImuLimits{config.imu.accel_range_mps2, config.imu.gyro_range_radps}),
      mounting_(mounting),
      replay_(replay),
      time_offset_s_(config.imu.time_offset_s),
      readings_(1024, Overflow::drop_oldest, [] { return slam::ImuSample{}; }) {
  stats_.time_offset_s.store(time_offset_s_);
}

std::uint64_t PacketImu::count_packet() {
  const std::uint64_t n = ++packets_;
  stats_.packets.store(n, std::memory_order_relaxed);
  return n;
}

bool PacketImu::near_lidar(const drivers::ClockEstimate& lidar, std::int64_t sensor_ns) {
  return std::abs(static_cast<double>(sensor_ns) - static_cast<double>(lidar.at_sensor_ns)) <= kMaxFromLidarNs;
}

void PacketImu::hand_on(const Eigen::Vector3d& specific_force, const Eigen::Vector3d& angular_rate,
                        std::int64_t sensor_ns, const drivers::ClockOffsetEstimator& lidar_clock, std::uint64_t n,
                        std::int64_t received_mono_ns) {
  slam::ImuSample r;
  r.t = 1e-9 * static_cast<double>(lidar_clock.to_host(sensor_ns)) - time_offset_s_;
  r.specific_force = specific_force;
  r.angular_rate = angular_rate;
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
  if (pose_feed_ != nullptr) pose_feed_->reading(r, received_mono_ns);
}

void PacketImu::catch_up(double until_t, const std::function<bool()>& idle) {
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
