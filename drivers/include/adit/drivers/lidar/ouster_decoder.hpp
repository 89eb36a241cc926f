#pragma once
// The LidarDecoder for Ouster OS0/OS1/OS2 (32-128 beams), every lidar profile
// of ouster_packet.hpp, configured by the sensor's metadata.
//
// Points: one per pixel and return with a non-zero range, in the sensor frame
// (metres), by the XYZ equations of the Ouster firmware user manual ("Sensor
// Data > Coordinate Frames and XYZ Calculation > Lidar Range to XYZ"):
//   θe = 2π(1 - mid/W), θa = -2π·azimuth_i/360, φ = 2π·altitude_i/360,
//   n  = sqrt(b2l[0][3]² + b2l[2][3]²)   (the beam origin offset),
//   x  = (r - n)·cos(θe+θa)·cos φ + b2l[0][3]·cos θe
//   y  = (r - n)·sin(θe+θa)·cos φ + b2l[0][3]·sin θe
//   z  = (r - n)·sin φ + b2l[2][3]
// then lidar_to_sensor_transform, then mm -> m. All of it except r is
// precomputed per (row, column) at construction: a point is r·d + o.
//
// Per point: intensity = reflectivity, range_m = range (exactly range_mm/1000:
// the integer comes back by rounding), signal and near_ir raw, ring = beam
// index counted from the lowest beam, sensor_time_ns = the column's
// timestamp, azimuth_deg = 360·mid/W (the column's encoder angle in the
// direction of rotation, so scans are cut between columns, never through one).
// The raw fields ride in LidarPoint (see point.hpp) rather than beside it, so
// they survive the ScanAssembler like every other field.
// sequence = frame_id·P + packet index in the frame (P = packets per frame),
// so the ScanAssembler counts lost packets; it wraps at sequence_modulus().

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "adit/drivers/lidar/decoder.hpp"
#include "adit/drivers/lidar/ouster_metadata.hpp"
#include "adit/drivers/lidar/ouster_packet.hpp"

namespace adit::drivers {

struct OusterDecoderCounters {
  std::uint64_t lidar_packets = 0;
  std::uint64_t imu_packets = 0;
  std::uint64_t invalid_columns = 0;  // status bit clear: not measured (outside the window, ...)
};

class OusterDecoder final : public LidarDecoder {
 public:
  explicit OusterDecoder(const OusterMetadata& metadata);

  std::string_view model() const override { return model_; }
  std::uint16_t default_port() const override { return port_; }
  std::size_t max_points_per_packet() const override { return points_.size(); }
  std::int64_t min_packet_period_ns() const override { return packet_period_ns_; }
  std::size_t max_packet_bytes() const override;  // the lidar packet's or the IMU packet's
  DecodedPacket decode(std::span<const std::uint8_t> payload, std::int64_t host_time_ns) override;

  // The last IMU packet decoded (decode() returns `auxiliary` for them).
  const OusterImuSample& last_imu() const { return imu_; }
  const OusterDecoderCounters& counters() const { return counters_; }
  const OusterPacketLayout& layout() const { return layout_; }
  // frame_id (16 bits) × packets per frame.
  std::uint64_t sequence_modulus() const override { return std::uint64_t{65536} * packets_per_frame_; }
  std::uint32_t packets_per_frame() const { return packets_per_frame_; }
  // Time between lidar packets (0 when the frame rate is unknown).
  std::int64_t packet_period_ns() const { return packet_period_ns_; }

  // One pixel's precomputed ray: point = range_mm * d + o, in metres.
  // Public only so the profile-templated loop in the .cpp can name it.
  struct Ray {
    float dx, dy, dz, ox, oy, oz;
  };

 private:
  OusterPacketLayout layout_;
  std::string model_;
  std::uint16_t port_;
  int width_;
  int height_;
  std::uint32_t packets_per_frame_;
  std::int64_t packet_period_ns_;
  std::vector<Ray> rays_;  // [column * H + row]
  std::vector<float> column_azimuth_deg_;
  std::vector<std::uint16_t> rings_;
  std::vector<DecodedPoint> points_;
  OusterImuSample imu_;
  OusterDecoderCounters counters_;
};

}  // namespace adit::drivers
