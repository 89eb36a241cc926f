#pragma once
// The Ouster LiDAR's own IMU (config `imu.source: ouster`) as an ImuSource.
//
// In:   the IMU packets (48 bytes, IMU profile LEGACY, UDP port 7503 by the
//       sensor's metadata) that LidarSource receives beside the LiDAR's, from
//       the same pcap (paced with the LiDAR packets) or live from a socket of
//       their own; they reach push() on LidarSource's assembly thread, in
//       arrival order with the LiDAR packets.
// Out:  slam::ImuSample readings: accelerometer and gyroscope decoded by
//       drivers::decode_ouster_imu, checked by ImuMonitor, turned from the
//       IMU's axes into the body's (the metadata's imu_to_sensor_transform,
//       then lidar.extrinsics), stamped at accel_time_ns mapped to the host
//       clock by the LiDAR stream's own sensor-clock estimate (the one its
//       scans' start_time_ns come from, drivers/lidar/sensor_clock.hpp) minus
//       imu.time_offset_s. Readings before that estimate exists, or stamped
//       more than 10 s from the LiDAR's newest packet (a corrupt packet), are
//       dropped (counted `unclocked`). The hand-off to the odometry is
//       PacketImu's (packet_imu.hpp). No allocation, lock or log per packet.

#include <cstdint>
#include <span>

#include <Eigen/Core>

#include "adit/config/config.hpp"
#include "adit/daemon/packet_imu.hpp"
#include "adit/drivers/lidar/ouster_metadata.hpp"
#include "adit/drivers/lidar/sensor_clock.hpp"

namespace adit::daemon {

// The IMU's pose in the body frame: the metadata's imu_to_sensor_transform
// (row-major 4×4, mm) then the LiDAR's extrinsics. Throws adit::InputError
// naming `metadata_file` when its rotation is not one.
ImuMounting ouster_imu_mounting(const drivers::OusterMetadata& metadata, const config::Transform& lidar_extrinsics,
                                const std::string& metadata_file);

class OusterImu final : public PacketImu {
 public:
  // `replay`: catch_up waits for the readings of a scan (pcap source).
  // Throws adit::InputError naming the metadata file when its IMU profile is not LEGACY.
  OusterImu(const config::Config& config, const drivers::OusterMetadata& metadata, bool replay);

  std::uint16_t port() const { return port_; }

  // Assembly thread: one datagram from the IMU port, received at
  // `host_time_ns` (monotonic: `received_mono_ns`); `lidar_clock` is the
  // LiDAR stream's sensor-clock estimate.
  void push(std::span<const std::uint8_t> payload, std::int64_t host_time_ns, std::int64_t received_mono_ns,
            const drivers::ClockOffsetEstimator& lidar_clock) override;

  const char* imu_name() const override { return "ouster"; }

 private:
  std::uint16_t port_;
  drivers::ClockOffsetEstimator packet_clock_;  // the IMU packets' own (system time, host time) pairs
};

}  // namespace adit::daemon
