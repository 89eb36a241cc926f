#pragma once
// A Livox LiDAR's own IMU (config `imu.source: livox`) as an ImuSource.
//
// In:   the IMU packets LidarSource receives beside the LiDAR's: the
//       Mid-360's SDK2 packets on their own port (drivers::livox_imu_port,
//       56401; from the same pcap or a socket of their own), the Avia's SDK1
//       packets among its points on the data port (those the decoder reports
//       `auxiliary`); they reach push() on LidarSource's assembly thread, in
//       arrival order with the LiDAR packets.
// Out:  OusterImu's contract (ouster_imu.hpp, PacketImu) with the Livox
//       packet: readings decoded by drivers::decode_livox_imu (gyroscope
//       rad/s, accelerometer converted from g), checked by ImuMonitor, turned
//       into the body's axes by the mounting, stamped with the packet's
//       timestamp (the same sensor clock as the points) mapped to the host
//       clock by the LiDAR stream's own estimate, minus imu.time_offset_s.
//       No allocation, lock or log per packet.

#include <cstdint>
#include <span>

#include <Eigen/Geometry>

#include "adit/config/config.hpp"
#include "adit/daemon/packet_imu.hpp"
#include "adit/drivers/lidar/livox.hpp"
#include "adit/drivers/lidar/sensor_clock.hpp"

namespace adit::daemon {

// The model's IMU in its point frame (drivers::livox_imu_position_m, axes
// parallel), then the LiDAR's extrinsics.
ImuMounting livox_imu_mounting(drivers::LivoxModel model, const config::Transform& lidar_extrinsics);

class LivoxImu final : public PacketImu {
 public:
  // `replay`: catch_up waits for the readings of a scan (pcap source).
  LivoxImu(const config::Config& config, const ImuMounting& mounting, bool replay);

  // Assembly thread: one IMU datagram received at `host_time_ns`; `lidar_clock` is the LiDAR stream's estimate.
  void push(std::span<const std::uint8_t> payload, std::int64_t host_time_ns, std::int64_t received_mono_ns,
            const drivers::ClockOffsetEstimator& lidar_clock) override;

  const char* imu_name() const override { return "livox"; }
};

}  // namespace adit::daemon
