#pragma once
// A Livox LiDAR's own IMU (Mid-360: SDK2 packets to UDP 56401; Avia: SDK1
// packets among its points) as an ImuSource: the adapter for a future
// `imu.source: livox`. It is OusterImu's contract (ouster_imu.hpp, PacketImu) with
// the Livox packet: readings decoded by drivers::decode_livox_imu (gyroscope
// rad/s, accelerometer converted from g), checked by ImuMonitor, turned into
// the body's axes by the mounting, stamped with the packet's timestamp (the
// same sensor clock as the points) mapped to the host clock by the LiDAR
// stream's own estimate, minus imu.time_offset_s. Not wired into LidarSource
// yet (docs/LIDAR-LIVOX.md says how). No allocation, lock or log per packet.

#include <cstdint>
#include <span>

#include <Eigen/Geometry>

#include "adit/config/config.hpp"
#include "adit/daemon/packet_imu.hpp"
#include "adit/drivers/lidar/sensor_clock.hpp"

namespace adit::daemon {

// The Mid-360's IMU in its point frame (Livox Mid-360 user manual: x 11.0,
// y 23.29, z −44.12 mm, axes parallel), then the LiDAR's extrinsics.
ImuMounting livox_mid360_imu_mounting(const config::Transform& lidar_extrinsics);

class LivoxImu final : public PacketImu {
 public:
  // `replay`: catch_up waits for the readings of a scan (pcap source).
  LivoxImu(const config::Config& config, const ImuMounting& mounting, bool replay);

  // Assembly thread: one IMU datagram received at `host_time_ns`; `lidar_clock` is the LiDAR stream's estimate.
  void push(std::span<const std::uint8_t> payload, std::int64_t host_time_ns,
            const drivers::ClockOffsetEstimator& lidar_clock);

  const char* imu_name() const override { return "livox"; }
};

}  // namespace adit::daemon
