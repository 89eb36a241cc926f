#pragma once
// The decode + assemble loop shared by the pcap tools, the live receiver and
// the tests: feed datagrams in, get scans out, with every packet counted by
// its status. Nothing here allocates per packet. Bad packets are counted and
// skipped; a warning with the counts is logged at most once per
// kBadPacketLogPeriodNs of host time.

#include <array>
#include <cstdint>
#include <functional>

#include "adit/drivers/lidar/decoder.hpp"
#include "adit/drivers/lidar/scan_assembler.hpp"
#include "adit/drivers/lidar/sensor_clock.hpp"

namespace adit::drivers {

struct PacketCounters {
  std::array<std::uint64_t, 5> by_status{};  // indexed by PacketStatus
  std::uint64_t count(PacketStatus s) const { return by_status[static_cast<std::size_t>(s)]; }
  std::uint64_t total() const;
};

class DecodeStream {
 public:
  using ScanHandler = std::function<void(LidarScan&)>;

  // The decoder and assembler are borrowed and must outlive the stream.
  DecodeStream(LidarDecoder& decoder, ScanAssembler& assembler, ScanHandler on_scan);

  // One UDP payload received at `host_time_ns` (kernel or capture timestamp).
  PacketStatus push(std::span<const std::uint8_t> payload, std::int64_t host_time_ns);
  // End of the stream: emits the partial scan in progress.
  void finish();

  const PacketCounters& counters() const { return counters_; }
  std::uint64_t bad_packets() const;

  static constexpr std::int64_t kBadPacketLogPeriodNs = 10'000'000'000;
  const ClockOffsetEstimator& clock() const { return clock_; }
  // Sensor time of the last data packet.
  std::int64_t last_sensor_time_ns() const { return last_sensor_time_ns_; }

 private:
  LidarDecoder& decoder_;
  ScanAssembler& assembler_;
  ScanHandler on_scan_;
  PacketCounters counters_;
  ClockOffsetEstimator clock_;
  std::int64_t last_sensor_time_ns_ = 0;
  std::int64_t last_bad_log_ns_ = 0;
};

// An assembler configuration for a decoder: room for `max_scan_ns` of packets
// (default: one revolution at 5 Hz, the slowest rate these sensors run at) at
// `packet_period_ns`, or when that is 0 at the decoder's min_packet_period_ns
// (4096 packets when it has none).
ScanAssemblerConfig assembler_config_for(const LidarDecoder& decoder, std::int64_t packet_period_ns,
                                         float cut_azimuth_deg, std::int64_t max_scan_ns = 200'000'000);

}  // namespace adit::drivers
