#pragma once
// What the pipeline counts and times, written by its stages' threads and read
// by the session (status, summary.json) and the tools.

#include <atomic>
#include <string_view>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "adit/daemon/imu_stats.hpp"

namespace adit::daemon {

// Statistics, readable while running (atomics) and complete after join().
enum class RecordingStop : int {
  recording = 0,
  budget = 1,       // session.record_budget_mb reached
  write_failed = 2, // the disk refused a write (full)
  low_disk = 3,     // free space fell below session.record_min_free_mb
};
constexpr std::string_view to_string(RecordingStop why) {
  switch (why) {
    case RecordingStop::recording: return "recording";
    case RecordingStop::budget: return "the session's recording budget (session.record_budget_mb) is used up";
    case RecordingStop::write_failed: return "the disk refused a write (full?)";
    case RecordingStop::low_disk: return "free disk space fell below session.record_min_free_mb";
  }
  return "unknown";
}

struct PipelineStats {
  std::atomic<std::uint64_t> datagrams{0};         // received from the source
  std::atomic<std::uint64_t> foreign_datagrams{0}; // not on the data port
  std::atomic<std::uint64_t> stale_datagrams{0};   // udp: in the socket before start(), discarded
  std::atomic<std::uint64_t> dropped_packets{0};   // live: dropped because assembly fell behind
  // udp: dropped by the kernel because the socket's receive buffer was full
  // (SO_RXQ_OVFL; the receiver was held up). The assembler also counts them
  // among missing_packets, where they look like link loss: this says whose.
  std::atomic<std::uint64_t> socket_drops{0};
  std::atomic<std::uint64_t> scans{0};
  std::atomic<std::uint64_t> dropped_scans{0};     // live: dropped because odometry fell behind
  std::atomic<std::uint64_t> incomplete_scans{0};
  std::atomic<std::uint64_t> skipped_start_scans{0};  // 0 or 1: an incomplete first scan, from which no map starts
  std::atomic<std::uint64_t> poses{0};
  std::atomic<std::uint64_t> invalid_poses{0};
  std::atomic<std::uint64_t> degenerate_poses{0};
  std::atomic<std::uint64_t> lost_poses{0};         // the fit collapsed: held, kept out of the map
  std::atomic<std::uint64_t> relocalised_poses{0};  // tracked again after lost ones
  std::atomic<std::uint64_t> searches_cut{0};       // a rotation or start search stopped short: scans were waiting
  std::atomic<std::uint64_t> bad_packets{0};
  // The link as the scan assembler sees it (drivers/lidar/scan_assembler.hpp):
  // packets missing from the sequence, repeated, arriving late (skipped), and
  // jumps too large to be loss (a sensor restart, a clock step).
  std::atomic<std::uint64_t> missing_packets{0};
  std::atomic<std::uint64_t> duplicate_packets{0};
  std::atomic<std::uint64_t> late_packets{0};
  std::atomic<std::uint64_t> resyncs{0};
  std::atomic<std::int64_t> last_packet_realtime_ns{0};  // wall clock of the newest datagram
  std::atomic<std::int64_t> last_packet_mono_ns{0};      // its monotonic time (silence is measured on this)
  std::atomic<std::uint64_t> silences{0};                // the LiDAR silent > 1 s (cable, power), by its packets' stamps
  std::atomic<std::int64_t> longest_silence_ns{0};
  std::atomic<std::uint64_t> clock_steps{0};             // live: the host's wall clock stepped (NTP, PTP), ≥ 0.1 s
  std::atomic<std::int64_t> last_clock_step_ns{0};       // the newest step, signed (+: the wall clock jumped ahead)
  std::atomic<std::int64_t> clock_offset_ns{0};          // host − sensor clock, per scan (drivers/lidar/sensor_clock.hpp)
  std::atomic<std::uint64_t> recorded_datagrams{0};
  std::atomic<std::uint64_t> recorded_bytes{0};
  // Why the raw recording stopped before the session did (RecordingStop);
  // the mapping goes on either way.
  std::atomic<int> recording_stopped{0};
  std::atomic<std::uint64_t> mapped_scans{0};
  std::atomic<std::uint64_t> dropped_map_scans{0};      // live: mapping fell behind
  std::atomic<std::uint64_t> map_points{0};
  std::atomic<std::uint64_t> map_tiles{0};
  std::atomic<std::uint64_t> keyframes{0};
  // What the mapping thread holds and sends away (eviction: tiles the sensor has left go to disk).
  std::atomic<std::uint64_t> map_bytes{0};            // resident tiles' vectors and indices
  std::atomic<std::uint64_t> map_bytes_peak{0};       // the most they held at a keyframe, before evicting and compacting
  std::atomic<std::uint64_t> keyframe_bytes{0};       // keyframes' downsampled scans
  std::atomic<std::uint64_t> resident_tiles{0};
  std::atomic<std::uint64_t> grid_patches{0};         // the live 2D grid's patches
  std::atomic<std::uint64_t> evicted_tiles{0};        // evictions (a tile evicted twice counts twice)
  std::atomic<std::uint64_t> restored_tiles{0};       // evicted tiles read back because the sensor returned
  std::atomic<std::uint64_t> tiles_checked_for_loops{0};  // live tiles checked against a new loop correction
  std::atomic<std::uint64_t> tiles_checked_by_corners{0};  // ... of them, found unmoved from their corners alone
  std::atomic<std::uint64_t> tiles_moved_by_loops{0};     // ... and sent again, moved (map.loops_move_map)
  std::atomic<std::uint64_t> points_moved_by_loops{0};    // their points
  std::atomic<std::uint64_t> revisit_points{0};           // not added: an earlier pass mapped their place (map.merge_revisits)
  std::atomic<std::uint64_t> compacted_tiles{0};      // crowded tiles written out, keeping a bit per voxel
  std::atomic<std::uint64_t> lost_candidates{0};      // voxels hit < min_hits times in evicted tiles
  std::atomic<std::uint64_t> spilled_keyframes{0};    // keyframes whose scan went to keyframes_dir
  std::atomic<std::uint64_t> tile_file_errors{0};     // a tile or keyframe that could not be written (kept) or read (skipped)
  std::atomic<std::uint64_t> dropped_in_evicted{0};   // points not mapped: their tile could not be read back
  // The loop-closure thread's counts (loop_closure_stage.hpp).
  std::atomic<std::uint64_t> loop_keyframes{0};       // keyframes in the pose graph
  std::atomic<std::uint64_t> loop_candidates{0};      // found by place recognition
  std::atomic<std::uint64_t> loops_accepted{0};       // in the graph
  std::atomic<std::uint64_t> loops_rejected{0};       // refused by verification or the guard
  std::atomic<std::int64_t> last_loop_realtime_ns{0};  // wall clock when the newest loop was accepted; 0: none
  std::atomic<std::uint64_t> wheel_priors{0};          // scans registered with the wheels' prior
  std::atomic<std::uint64_t> scans_without_wheels{0};  // wheels configured, but no samples around the scan
  std::atomic<std::uint64_t> scans_wheels_held{0};     // a wheel held for slip over the scan's interval: no wheel prior
  std::atomic<std::uint64_t> gyro_priors{0};           // wheel priors turned by the gyroscope (gyrodometry)
  std::atomic<std::uint64_t> gyro_refused{0};          // the gyroscope disagreed with the wheels: their turn kept
  std::atomic<std::uint64_t> gyro_still{0};            // scans whose standstill taught the gyroscope's bias
  std::atomic<std::uint64_t> gravity_priors{0};        // scans registered with the accelerometer's up
  std::atomic<std::uint64_t> scans_without_gravity{0}; // IMU and wheels configured, but no readings or not gravity-sized
  // The IMU source's figures (imu.enabled; imu_stats.hpp: rate, gaps,
  // saturation, stuck axes, time going back, clock offsets), copied from the
  // source by the odometry thread after each scan and at the end.
  ImuStats imu;
};

// A stage's queue and its thread's CPU time, for the status message.
struct StageLoad {
  std::string name;
  double cpu_s = 0.0;         // CPU time of the stage's thread so far
  std::size_t queue_depth = 0;  // items waiting for the stage
  std::size_t queue_capacity = 0;
};

// Scans whose figures PipelineTimings keeps (29 h at 10 Hz).
inline constexpr std::size_t kTimingCapacity = std::size_t{1} << 20;

// Per-scan figures gathered by the odometry and output threads (read after join()).
struct PipelineTimings {
  std::vector<double> odometry_ms;   // Odometry::process per scan
  std::vector<double> latency_ms;    // last packet of a scan received → its pose handed on
  std::vector<double> grid_ms;       // slam::LiveGrid::insert per mapped scan (mapping thread)
  double duration_s = 0.0;           // wall time from start to the source's end and the queues drained
  double sensor_span_s = 0.0;        // first to last scan stamp
};

}  // namespace adit::daemon
