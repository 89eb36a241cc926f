#pragma once
// The packet-to-pose pipeline of aditd, one thread per stage, joined by
// preallocated lock-free hand-offs (handoff.hpp):
//
//   receiver ─packets→ assembly ─scans→ odometry ─poses→ output
//                                                 └─scans+poses→ mapping
//
// The receiver reads UDP (live: a full hand-off drops the oldest packet) or a
// pcap / scan directory (replay: it waits, nothing is lost), and can record
// the raw packets. Assembly decodes and cuts scans; odometry runs
// slam::Odometry; output writes the trajectory, keeps statistics and hands
// each pose to the pose sink; mapping deskews each registered scan with the
// corrected motion, adds it to the session's tiled map, keeps keyframes and
// hands changed tiles to the tile sink at most once per period. After
// start-up no stage before mapping allocates per packet or per scan (the map
// grows by nature). `adit replay` runs the same class.

#include <atomic>
#include <functional>
#include <span>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "adit/config/config.hpp"
#include "adit/daemon/heartbeat.hpp"
#include "adit/daemon/tile_spill.hpp"
#include "adit/slam/keyframes.hpp"
#include "adit/slam/odometry.hpp"
#include "adit/slam/tiled_map.hpp"

namespace adit::daemon {

// Where results leave the pipeline. Each runs on one pipeline thread and must
// be quick and not throw; empty = not wanted.
struct PipelineSinks {
  // Output thread, once per scan (valid or not).
  std::function<void(const slam::OdometryResult&)> pose;
  // Mapping thread: the whole current content of a tile that changed.
  std::function<void(const slam::TileCoord&, std::span<const slam::MapSample>)> tile;
};

struct PipelineOptions {
  std::filesystem::path trajectory_file;  // TUM, written as poses arrive; empty = none
  // TUM: each mapped scan's pose as the map placed it (with map.refine, the
  // refined pose; the published one is the odometry's); empty = none.
  std::filesystem::path map_trajectory_file;
  std::filesystem::path record_file;      // raw LiDAR packets as pcap; empty = none
  double replay_speed = -1.0;             // pcap/scan_dir: overrides lidar.replay_speed when ≥ 0
  slam::OdometryConfig odometry;          // range limits come from the lidar section
  bool mapping = true;                    // run the mapping thread (config `map` section)
  PipelineSinks sinks;
};

// Statistics, readable while running (atomics) and complete after join().
struct PipelineStats {
  std::atomic<std::uint64_t> datagrams{0};         // received from the source
  std::atomic<std::uint64_t> foreign_datagrams{0}; // not on the data port
  std::atomic<std::uint64_t> stale_datagrams{0};   // udp: in the socket before start(), discarded
  std::atomic<std::uint64_t> dropped_packets{0};   // live: dropped because assembly fell behind
  std::atomic<std::uint64_t> scans{0};
  std::atomic<std::uint64_t> dropped_scans{0};     // live: dropped because odometry fell behind
  std::atomic<std::uint64_t> incomplete_scans{0};
  std::atomic<std::uint64_t> poses{0};
  std::atomic<std::uint64_t> invalid_poses{0};
  std::atomic<std::uint64_t> degenerate_poses{0};
  std::atomic<std::uint64_t> bad_packets{0};
  std::atomic<std::int64_t> last_packet_realtime_ns{0};  // wall clock of the newest datagram
  std::atomic<std::int64_t> clock_offset_ns{0};          // host − sensor clock, per scan (drivers/lidar/sensor_clock.hpp)
  std::atomic<std::uint64_t> recorded_datagrams{0};
  std::atomic<std::uint64_t> mapped_scans{0};
  std::atomic<std::uint64_t> dropped_map_scans{0};      // live: mapping fell behind
  std::atomic<std::uint64_t> map_points{0};
  std::atomic<std::uint64_t> map_tiles{0};
  std::atomic<std::uint64_t> keyframes{0};
  // What the mapping thread holds and sends away (eviction: tiles the sensor has left go to disk).
  std::atomic<std::uint64_t> map_bytes{0};            // resident tiles' vectors and indices
  std::atomic<std::uint64_t> keyframe_bytes{0};       // keyframes' downsampled scans
  std::atomic<std::uint64_t> resident_tiles{0};
  std::atomic<std::uint64_t> evicted_tiles{0};        // evictions (a tile evicted twice counts twice)
  std::atomic<std::uint64_t> restored_tiles{0};       // evicted tiles read back because the sensor returned
  std::atomic<std::uint64_t> compacted_tiles{0};      // crowded tiles written out, keeping a bit per voxel
  std::atomic<std::uint64_t> lost_candidates{0};      // voxels hit < min_hits times in evicted tiles
  std::atomic<std::uint64_t> spilled_keyframes{0};    // keyframes whose scan went to keyframes_dir
  std::atomic<std::uint64_t> tile_file_errors{0};     // a tile or keyframe that could not be written (kept) or read (skipped)
  std::atomic<std::uint64_t> dropped_in_evicted{0};   // points not mapped: their tile could not be read back
  std::atomic<std::uint64_t> wheel_priors{0};          // scans registered with the wheels' prior
  std::atomic<std::uint64_t> scans_without_wheels{0};  // wheels configured, but no samples around the scan
  std::atomic<std::uint64_t> gravity_priors{0};        // scans registered with the accelerometer's up
  std::atomic<std::uint64_t> scans_without_gravity{0}; // IMU configured, but no readings or not gravity-sized
};

// A stage's queue and its thread's CPU time, for the status message.
struct StageLoad {
  std::string name;
  double cpu_s = 0.0;         // CPU time of the stage's thread so far
  std::size_t queue_depth = 0;  // items waiting for the stage
  std::size_t queue_capacity = 0;
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

// Files a session's pipeline writes, given at start() so that a pipeline can be
// built (and its memory allocated) before its session begins.
struct SessionFiles {
  std::filesystem::path trajectory_file;  // TUM; empty = none (or PipelineOptions')
  std::filesystem::path map_trajectory_file;  // TUM, the map's poses; empty = none (or PipelineOptions')
  std::filesystem::path record_file;      // raw packets as pcap; empty = none
  std::filesystem::path can_record_file;  // the CAN bus as candump -L; empty = none
  // Where tiles the sensor has left are written (tiles/<id>.adt) so they can
  // leave RAM (map.evict_after_keyframes); empty = every tile stays in RAM.
  std::filesystem::path tiles_dir;
  // Where the scans of keyframes the sensor has left are written
  // (<stamp_ns>.ply, body frame) so that only their poses stay in RAM; empty = all stay.
  std::filesystem::path keyframes_dir;
};

class Pipeline {
 public:
  // Opens the source and builds every stage; throws adit::InputError for bad
  // files or settings (named), before any thread starts.
  Pipeline(const config::Config& config, const PipelineOptions& options);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  // Opens `files` (throws adit::InputError naming one that cannot be written)
  // and starts the threads. Once per pipeline.
  void start(const SessionFiles& files = {});
  // Stops at once: queued packets and scans are dropped.
  void request_stop();
  // Stops reading the source; what was read is still processed, so drained()
  // becomes true once every stage has caught up (the end of a session).
  void end_source();
  // Waits until a replay source is exhausted and every stage has drained, or
  // until request_stop(); then joins the threads.
  void join();
  // Every stage has ended: a replay source is exhausted and drained, or a stop was requested.
  bool drained() const;

  const PipelineStats& stats() const;
  const PipelineTimings& timings() const;  // after join()
  std::vector<const Heartbeat*> heartbeats() const;
  std::vector<std::string> warnings() const;  // thread settings that could not be applied
  std::vector<StageLoad> loads() const;         // while running

  // The session's map and keyframes: complete after join(), not to be read before.
  // Evicted tiles are not in map() (see map().evicted_coords()) but in tile_spill();
  // a keyframe whose points are empty had them written to SessionFiles::keyframes_dir.
  const slam::TiledVoxelMap& map() const;
  const TileSpill* tile_spill() const;  // null without SessionFiles::tiles_dir
  const std::vector<slam::Keyframe>& keyframes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace adit::daemon
