#pragma once
// The packet-to-pose pipeline of aditd, one thread per stage, joined by
// preallocated lock-free hand-offs (handoff.hpp):
//
//   receiver ─packets→ assembly ─scans→ odometry ─poses→ output
//
// The receiver reads UDP (live: a full hand-off drops the oldest packet) or a
// pcap / scan directory (replay: it waits, nothing is lost). Assembly decodes
// and cuts scans; odometry runs slam::Odometry; output writes the trajectory
// and keeps statistics (mapping and publishing attach here). After start-up no
// stage allocates per packet or per scan. `adit replay` runs the same class.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "adit/config/config.hpp"
#include "adit/daemon/heartbeat.hpp"
#include "adit/slam/odometry.hpp"

namespace adit::daemon {

struct PipelineOptions {
  std::filesystem::path trajectory_file;  // TUM, written as poses arrive; empty = none
  double replay_speed = -1.0;             // pcap/scan_dir: overrides lidar.replay_speed when ≥ 0
  slam::OdometryConfig odometry;          // range limits come from the lidar section
};

// Statistics, readable while running (atomics) and complete after join().
struct PipelineStats {
  std::atomic<std::uint64_t> datagrams{0};         // received from the source
  std::atomic<std::uint64_t> foreign_datagrams{0}; // not on the data port
  std::atomic<std::uint64_t> dropped_packets{0};   // live: dropped because assembly fell behind
  std::atomic<std::uint64_t> scans{0};
  std::atomic<std::uint64_t> dropped_scans{0};     // live: dropped because odometry fell behind
  std::atomic<std::uint64_t> incomplete_scans{0};
  std::atomic<std::uint64_t> poses{0};
  std::atomic<std::uint64_t> invalid_poses{0};
  std::atomic<std::uint64_t> degenerate_poses{0};
  std::atomic<std::uint64_t> bad_packets{0};
};

// The q-quantile (0..1) of `values` by nearest rank; 0 when empty.
double quantile(std::vector<double> values, double q);

// Per-scan figures gathered by the odometry and output threads (read after join()).
struct PipelineTimings {
  std::vector<double> odometry_ms;   // Odometry::process per scan
  std::vector<double> latency_ms;    // last packet of a scan received → its pose handed on
  double duration_s = 0.0;           // wall time from start to the source's end and the queues drained
  double sensor_span_s = 0.0;        // first to last scan stamp
};

class Pipeline {
 public:
  // Opens the source and builds every stage; throws adit::InputError for bad
  // files or settings (named), before any thread starts.
  Pipeline(const config::Config& config, const PipelineOptions& options);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  void start();
  void request_stop();
  // Waits until a replay source is exhausted and every stage has drained, or
  // until request_stop(); then joins the threads.
  void join();
  // Every stage has ended: a replay source is exhausted and drained, or a stop was requested.
  bool drained() const;

  const PipelineStats& stats() const;
  const PipelineTimings& timings() const;  // after join()
  std::vector<const Heartbeat*> heartbeats() const;
  std::vector<std::string> warnings() const;  // thread settings that could not be applied

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace adit::daemon
