#pragma once
// Scan assembly: turns a stream of DecodedPackets into LidarScans, cut where
// the firing azimuth crosses a configurable angle, with per-point time offsets
// from the scan's first firing and counters of lost, repeated and late packets.
//
// It never waits: a lost packet is counted when the next one arrives, and a
// scan is emitted as soon as a firing past the cut azimuth shows up. All
// storage is reserved at construction (two scans of max_points_per_scan), so
// the steady state allocates nothing.
//
// Loss detection uses the packet's sequence number when the format has one,
// else its sensor time against the expected packet period.

#include <cstdint>

#include "adit/drivers/lidar/decoder.hpp"
#include "adit/drivers/lidar/point.hpp"

namespace adit::drivers {

struct ScanAssemblerConfig {
  float cut_azimuth_deg = 0.0F;          // a scan starts at the first firing at or past this azimuth
  std::size_t max_points_per_scan = 0;   // points beyond this are dropped and counted
  std::int64_t packet_period_ns = 0;     // expected time between data packets (0: no time-based loss counting)
  std::int64_t scan_period_ns = 0;       // one revolution; a scan is cut after 1.5 of these even without a crossing (0: never)
  std::uint64_t sequence_modulus = std::uint64_t{1} << 32;  // where the packet counter wraps
};

struct ScanAssemblerTotals {
  std::uint64_t packets = 0;       // data packets accepted into scans
  std::uint64_t scans = 0;         // scans emitted
  std::uint64_t complete_scans = 0;
  std::uint64_t missing_packets = 0;
  std::uint64_t duplicate_packets = 0;     // skipped
  std::uint64_t out_of_order_packets = 0;  // late packets, skipped
  std::uint64_t dropped_points = 0;        // over max_points_per_scan
  std::uint64_t resyncs = 0;               // jumps too large to be loss (sensor restart, clock step)
};

class ScanAssembler {
 public:
  explicit ScanAssembler(const ScanAssemblerConfig& config);

  // Adds one decoded packet (non-`ok` packets are ignored). Returns the scan
  // this packet finished, or nullptr. The scan stays valid, and may be
  // modified or swapped with a scan of the caller's, until the next add() or
  // flush(). `sensor_to_host_ns` is added to sensor times to give host times
  // (see SensorClock); 0 keeps LidarScan::start_time_ns on the sensor clock.
  LidarScan* add(const DecodedPacket& packet, std::int64_t sensor_to_host_ns = 0);

  // Emits the scan in progress (end of a stream), or nullptr when it is empty.
  // A flushed scan is never complete: it did not reach the cut.
  LidarScan* flush();

  const ScanAssemblerTotals& totals() const { return totals_; }
  const ScanAssemblerConfig& config() const { return config_; }
  // The packet period learnt from the first packet (a live source does not
  // know its return mode before it): turns on time-based loss counting.
  void set_packet_period_ns(std::int64_t period_ns) { config_.packet_period_ns = period_ns; }

  // Loss thresholds: a sequence or time jump beyond this many packets is a resync, not loss.
  static constexpr std::uint64_t kMaxCountedGap = 100'000;

 private:
  enum class Verdict : std::uint8_t { in_order, duplicate, late };
  Verdict classify(const DecodedPacket& packet);
  LidarScan* finish(bool reached_cut);
  void append(const DecodedPoint& point);
  float relative_azimuth(float azimuth_deg) const;

  ScanAssemblerConfig config_;
  ScanAssemblerTotals totals_;
  LidarScan scans_[2];
  int building_ = 0;            // index of the scan being filled
  bool started_at_cut_ = false; // the scan in progress began at a crossing
  bool armed_ = false;          // the scan has passed the far side of the revolution
  bool have_last_ = false;
  std::uint64_t last_sequence_ = 0;
  std::int64_t last_time_ns_ = 0;
  std::int64_t last_firing_ns_ = 0;  // of the last accepted packet
  bool have_rel_ = false;
  float last_rel_ = 0.0F;            // azimuth of the last firing, relative to the cut
  std::int64_t sensor_to_host_ns_ = 0;
};

}  // namespace adit::drivers
