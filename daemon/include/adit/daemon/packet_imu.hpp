#pragma once
// What a LiDAR's own IMU shares, whatever its packet (OusterImu, LivoxImu):
// a decoded reading, stamped on the sensor's clock, is put on the host clock
// by the LiDAR stream's estimate (minus imu.time_offset_s), checked by
// ImuMonitor, turned into the body's axes by the mounting and handed to the
// odometry thread, which keeps it in its history.
//
// The hand-off drops the oldest reading when full, in replay too: the
// assembly thread must never wait for the odometry here, which waits for
// the assembly's scans (a LiDAR that stops while the IMU goes on would
// otherwise deadlock them); 1024 readings are 10 s at 100 Hz, far more than
// a replay runs ahead. No allocation, lock or log per packet.

#include <atomic>
#include <cstdint>
#include <optional>
#include <span>

#include <Eigen/Core>

#include "adit/config/config.hpp"
#include "adit/daemon/handoff.hpp"
#include "adit/daemon/imu_monitor.hpp"
#include "adit/daemon/imu_source.hpp"
#include "adit/drivers/lidar/sensor_clock.hpp"

namespace adit::daemon {

class PacketImu : public ImuSource {
 public:
  // A stamp farther than this from the LiDAR's newest sensor time cannot be
  // put on its clock (nor added to it without overflowing): a corrupt packet,
  // counted `unclocked`.
  static constexpr double kMaxFromLidarNs = 10e9;

  // Assembly thread: the LiDAR stream has reached `t` (s, host clock): every
  // IMU packet that arrived before it has been pushed (a replay's catch_up
  // stops waiting once the LiDAR is 0.1 s past what it waits for).
  void lidar_reached(double t) { lidar_t_.store(t, std::memory_order_release); }
  // Assembly thread: one IMU datagram received at `host_time_ns`
  // (monotonic: `received_mono_ns`, from which the IMU-rate pose's latency
  // counts); `lidar_clock` is the LiDAR stream's sensor-clock estimate. A
  // damaged or unclockable packet is counted (ImuMonitor), never thrown.
  virtual void push(std::span<const std::uint8_t> payload, std::int64_t host_time_ns, std::int64_t received_mono_ns,
                    const drivers::ClockOffsetEstimator& lidar_clock) = 0;
  // Assembly thread: no more packets.
  void close() { readings_.close(); }

  // Live: what has arrived. A replay: until the readings or the LiDAR pass
  // until_t, or the source ends.
  void catch_up(double until_t, const std::function<bool()>& idle) override;
  const slam::ImuHistory& history() const override { return history_; }
  const ImuMounting& mounting() const override { return mounting_; }
  const ImuStats& imu_stats() const override { return stats_; }

 protected:
  // `replay`: catch_up waits for the readings of a scan (pcap source).
  PacketImu(const config::Config& config, const ImuMounting& mounting, bool replay);

  // Assembly thread: counts one more packet; its number, for the monitor's reports.
  std::uint64_t count_packet();
  // Whether `sensor_ns` can be put on the clock `lidar` estimates (kMaxFromLidarNs).
  static bool near_lidar(const drivers::ClockEstimate& lidar, std::int64_t sensor_ns);
  // Assembly thread: packet `n`'s reading in the IMU's axes, stamped at
  // `sensor_ns` on the sensor clock `lidar_clock` estimates (checked by
  // near_lidar), on to the odometry and the IMU-rate pose.
  void hand_on(const Eigen::Vector3d& specific_force, const Eigen::Vector3d& angular_rate, std::int64_t sensor_ns,
               const drivers::ClockOffsetEstimator& lidar_clock, std::uint64_t n, std::int64_t received_mono_ns);

  ImuStats stats_;
  ImuMonitor monitor_;

 private:
  ImuMounting mounting_;
  bool replay_;
  double time_offset_s_;
  Handoff<slam::ImuSample> readings_;
  std::uint64_t packets_ = 0;  // assembly thread
  std::atomic<double> lidar_t_{-1e300};
  slam::ImuHistory history_{kImuHistoryCapacity};  // odometry thread
};

}  // namespace adit::daemon
