#pragma once
// The interface every LiDAR family implements: one decoder per family
// (Velodyne, Hesai, RoboSense, Ouster), configured by the model's calibration.
//
// A decoder turns one UDP payload into points with their absolute firing time
// on the sensor clock and their azimuth. It writes into storage it allocated
// at construction (sized by max_points_per_packet) and returns a view of it,
// so the live path allocates nothing per packet. It never throws on packet
// content: bad packets come back with a status and are counted by the caller.
// Scan assembly (cutting at an azimuth, counting lost packets, turning firing
// times into offsets from the scan start) is the ScanAssembler's job.

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "adit/drivers/lidar/point.hpp"

namespace adit::drivers {

enum class PacketStatus : std::uint8_t {
  ok,         // a data packet, points decoded
  auxiliary,  // a valid non-point packet of this sensor (position, IMU, DIFOP); see the family's API
  foreign,    // not this sensor's packet (wrong size or magic); skipped
  truncated,  // this sensor's packet, cut short
  malformed,  // this sensor's packet with impossible content
};

std::string_view to_string(PacketStatus status);

// One decoded point before scan assembly.
struct DecodedPoint {
  LidarPoint point;              // time_offset_ns is filled in by the assembler
  float azimuth_deg = 0.0F;      // firing azimuth, [0, 360), in the sensor's rotation direction
  std::int64_t sensor_time_ns = 0;  // absolute firing time on the sensor clock
};

struct DecodedPacket {
  PacketStatus status = PacketStatus::foreign;
  std::int64_t sensor_time_ns = 0;          // the packet's first firing on the sensor clock
  std::optional<std::uint32_t> sequence;    // the packet counter, where the format has one
  std::span<const DecodedPoint> points;     // valid until the next decode() call
};

class LidarDecoder {
 public:
  virtual ~LidarDecoder() = default;
  LidarDecoder() = default;
  LidarDecoder(const LidarDecoder&) = delete;
  LidarDecoder& operator=(const LidarDecoder&) = delete;

  // The model's name as written in configs, e.g. "VLP-16", "PandarXT32".
  virtual std::string_view model() const = 0;
  // The UDP destination port of data packets, by default.
  virtual std::uint16_t default_port() const = 0;
  virtual std::size_t max_points_per_packet() const = 0;
  // The shortest time between this model's data packets in any return mode,
  // 0 when the decoder cannot tell before it sees packets: a scan's buffers
  // are sized from it (assembler_config_for), else for 4096 packets.
  virtual std::int64_t min_packet_period_ns() const { return 0; }
  // The longest datagram this decoder reads (data and auxiliary packets); the
  // packet pool before it (aditd's LiDAR source) keeps this many bytes a packet.
  virtual std::size_t max_packet_bytes() const { return 65'536; }
  // Where DecodedPacket::sequence wraps (for the ScanAssembler's loss counting).
  virtual std::uint64_t sequence_modulus() const { return std::uint64_t{1} << 32; }
  // host_time_ns (CLOCK_REALTIME) resolves sensor clocks that are ambiguous
  // on their own, like Velodyne's microseconds past the top of the hour.
  virtual DecodedPacket decode(std::span<const std::uint8_t> payload, std::int64_t host_time_ns) = 0;
};

}  // namespace adit::drivers
