#include "adit/drivers/lidar/decode_stream.hpp"

#include <numeric>

#include "adit/common/log.hpp"

namespace adit::drivers {

std::uint64_t PacketCounters::total() const { return std::accumulate(by_status.begin(), by_status.end(), std::uint64_t{0}); }

DecodeStream::DecodeStream(LidarDecoder& decoder, ScanAssembler& assembler, ScanHandler on_scan)
    : decoder_(decoder), assembler_(assembler), on_scan_(std::move(on_scan)) {}

PacketStatus DecodeStream::push(std::span<const std::uint8_t> payload, std::int64_t host_time_ns) {
  const DecodedPacket packet = decoder_.decode(payload, host_time_ns);
  ++counters_.by_status[static_cast<std::size_t>(packet.status)];
  if (packet.status != PacketStatus::ok) {
    if (packet.status != PacketStatus::auxiliary && host_time_ns - last_bad_log_ns_ >= kBadPacketLogPeriodNs) {
      last_bad_log_ns_ = host_time_ns;
      log::warn("{}: skipped {} bad packets so far ({} foreign, {} truncated, {} malformed)", decoder_.model(),
                bad_packets(), counters_.count(PacketStatus::foreign), counters_.count(PacketStatus::truncated),
                counters_.count(PacketStatus::malformed));
    }
    return packet.status;
  }
  last_sensor_time_ns_ = packet.sensor_time_ns;
  clock_.add(packet.sensor_time_ns, host_time_ns);
  const std::int64_t sensor_to_host = clock_.to_host(packet.sensor_time_ns) - packet.sensor_time_ns;
  if (LidarScan* scan = assembler_.add(packet, sensor_to_host); scan != nullptr && on_scan_) on_scan_(*scan);
  return packet.status;
}

std::uint64_t DecodeStream::bad_packets() const {
  return counters_.count(PacketStatus::foreign) + counters_.count(PacketStatus::truncated) +
         counters_.count(PacketStatus::malformed);
}

void DecodeStream::finish() {
  if (LidarScan* scan = assembler_.flush(); scan != nullptr && on_scan_) on_scan_(*scan);
}

ScanAssemblerConfig assembler_config_for(const LidarDecoder& decoder, std::int64_t packet_period_ns,
                                         float cut_azimuth_deg, std::int64_t max_scan_ns) {
  ScanAssemblerConfig config;
  config.cut_azimuth_deg = cut_azimuth_deg;
  config.packet_period_ns = packet_period_ns;
  config.sequence_modulus = decoder.sequence_modulus();
  // Room for the configured model's busiest mode (a VLP-16 in dual return at
  // 5 Hz: 303 packets, 116 352 points), not for any sensor's.
  const std::int64_t period = packet_period_ns > 0 ? packet_period_ns : decoder.min_packet_period_ns();
  const std::int64_t packets = period > 0 ? max_scan_ns / period + 2 : 4096;
  config.max_points_per_scan = static_cast<std::size_t>(packets) * decoder.max_points_per_packet();
  return config;
}

}  // namespace adit::drivers
