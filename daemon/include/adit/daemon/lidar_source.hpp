#pragma once
// The pipeline's first stage: LiDAR packets in, whole scans out.
//
// In:   UDP datagrams (live), a pcap file or a directory of scans (replay).
// Out:  scans in the sensor frame with per-point times (ScanSlot) through
//       scans(), each with when its last packet arrived; the raw packets as
//       pcap when a record file is open. With `imu.source: ouster` or
//       `livox`, the sensor's IMU packets (its IMU port: the Ouster's 7503,
//       the Mid-360's 56401; in the same pcap or on a socket of their own)
//       go through the same packet pool to imu() (OusterImu, LivoxImu), and
//       are recorded with the LiDAR's on their own port; the Avia's come
//       among its points and reach imu() as well.
// Threads: "receiver" reads the source into a pool of packets and records
// them; "assembly" decodes the packets and cuts scans (drivers::DecodeStream).
// A scan directory needs no assembly: the receiver hands its scans on. Live,
// a full hand-off drops the oldest packet or scan (counted); a replay waits,
// so nothing is lost. Neither thread allocates, locks or logs per packet;
// the recorder's buffered write is the only file output.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "adit/common/host_clock.hpp"
#include "adit/config/config.hpp"
#include "adit/daemon/handoff.hpp"
#include "adit/daemon/pipeline_items.hpp"
#include "adit/daemon/pipeline_stats.hpp"
#include "adit/daemon/stage_thread.hpp"

namespace adit::daemon {

class PacketImu;

class LidarSource {
 public:
  // Opens the source and builds the decoder; throws adit::InputError naming
  // the file or the config key. `replay_speed` ≥ 0 overrides lidar.replay_speed.
  // A scan of a directory source holds at most `scan_dir_points` points.
  // Live datagrams are stamped on `clock` (common/host_clock.hpp: the
  // session's step-free timeline; the CAN feed gets the same one).
  LidarSource(const config::Config& config, double replay_speed, std::size_t scan_dir_points, PipelineStats& stats,
              const std::atomic<bool>& stop, HostClock clock = HostClock());
  ~LidarSource();
  LidarSource(const LidarSource&) = delete;
  LidarSource& operator=(const LidarSource&) = delete;

  // Raw packets to `file` as pcap (throws adit::InputError naming it; a scan
  // directory cannot be recorded). Before start().
  void record_to(const std::filesystem::path& file);
  void start();
  // Stops reading the source; what was read still goes through.
  void end() { end_.store(true, std::memory_order_release); }
  void join();

  Handoff<ScanSlot>& scans() { return scans_; }
  Overflow overflow() const { return overflow_; }
  // The most points one scan can hold: the hand-offs after this stage reserve it.
  std::size_t max_points_per_scan() const { return max_points_; }

  // The LiDAR's own IMU (imu.source ouster or livox), or null.
  PacketImu* imu();

  std::vector<StageThread*> threads();
  std::size_t packets_waiting() const;
  std::size_t packet_capacity() const;
  // Bytes each pooled packet holds: the decoder's longest datagram and one more.
  std::size_t packet_bytes() const;

 private:
  struct Impl;
  std::atomic<bool> end_{false};
  std::unique_ptr<Impl> impl_;
  Overflow overflow_;
  std::size_t max_points_;
  Handoff<ScanSlot> scans_;
};

// The UDP port the LiDAR's own IMU sends to (imu.source ouster or livox):
// lidar.imu_port, else the Ouster's metadata (udp_port_imu) or the Livox
// model's; 0 without one. Throws adit::InputError for unreadable metadata.
std::uint16_t lidar_imu_port(const config::Config& c);

}  // namespace adit::daemon
