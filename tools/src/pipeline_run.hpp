#pragma once
// Running aditd's packet-to-pose Pipeline from a tool (`adit replay`,
// `adit bench pipeline`): the configuration with command-line overrides, a
// watch loop that samples the resident size once per pose, and the figures.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "adit/config/config.hpp"
#include "adit/daemon/pipeline.hpp"

namespace adit::tools {

// A configuration file and the keys a tool may override (empty = keep).
struct PipelineInputs {
  std::string config_file = "firmware-config/default.yaml";
  std::string pcap;         // lidar.source: pcap
  std::string scan_dir;     // lidar.source: scan_dir
  std::string can_log;      // candump -L log of the wheel encoders (can.source: candump)
  std::string model;        // lidar.model
  std::string calibration;  // lidar.calibration
};

// Loads and overrides; paths given on the command line stay relative to the
// working directory. Memory is never locked: these are desk tools, and locked
// pages would hide how the resident size grows. Throws adit::InputError.
config::Config load_pipeline_config(const PipelineInputs& inputs);

struct MemorySample {
  std::uint64_t poses = 0;  // poses handed on when sampled
  double resident_mb = 0.0;
  double heap_mb = -1.0;  // malloc's bytes in use; < 0: not sampled at this pose
  double map_mb = 0.0;    // the mapping thread's tiles in RAM (as of its last keyframe)
};

struct PipelineFigures {
  std::uint64_t datagrams = 0;
  std::uint64_t scans = 0;
  std::uint64_t incomplete_scans = 0;
  std::uint64_t skipped_start_scans = 0;  // 0 or 1: an incomplete first scan (no pose)
  std::uint64_t poses = 0;
  std::uint64_t invalid_poses = 0;
  std::uint64_t degenerate_poses = 0;
  std::uint64_t bad_packets = 0;
  std::uint64_t dropped_packets = 0;
  std::uint64_t socket_drops = 0;  // udp: the kernel's, the receive buffer full
  std::uint64_t dropped_scans = 0;
  double odometry_median_ms = 0.0;
  double odometry_p99_ms = 0.0;
  double latency_median_ms = 0.0;
  double latency_p99_ms = 0.0;
  double latency_max_ms = 0.0;
  double beyond_odometry_median_ms = 0.0;  // latency minus odometry time, per scan: queues and hand-offs
  double beyond_odometry_p99_ms = 0.0;
  double sensor_span_s = 0.0;  // first to last scan stamp
  double duration_s = 0.0;     // wall time
  double peak_resident_mb = 0.0;
  std::vector<MemorySample> memory;
  // Mapping: what it holds in RAM at the end and what it evicted to disk.
  bool mapping = false;
  std::uint64_t map_points = 0;
  std::uint64_t map_tiles = 0;
  std::uint64_t resident_tiles = 0;
  std::uint64_t evicted_tiles = 0;
  std::uint64_t restored_tiles = 0;
  std::uint64_t compacted_tiles = 0;
  std::uint64_t lost_candidates = 0;
  std::uint64_t tile_file_errors = 0;
  std::uint64_t keyframes = 0;
  std::uint64_t spilled_keyframes = 0;
  double map_mb = 0.0;       // resident tiles' structures
  double keyframe_mb = 0.0;  // keyframes' downsampled scans
  // The IMU-rate pose (daemon/imu_pose_feed.hpp): how many, and each one's
  // latency from its IMU packet's (or CAN frame's) arrival to the sink's return.
  bool imu_pose = false;
  std::uint64_t imu_poses = 0;
  double imu_pose_latency_median_ms = 0.0;
  double imu_pose_latency_p99_ms = 0.0;
  double imu_pose_latency_max_ms = 0.0;
  double speed() const { return duration_s > 0.0 ? sensor_span_s / duration_s : 0.0; }  // × real time
};

struct RunHooks {
  std::function<void()> started;    // called once the pipeline's threads run
  std::function<bool()> stop_when;  // polled; true stops the pipeline (live sources never drain)
};

// Starts the pipeline and waits until it has drained or `stop_when()` returns
// true (then stops it), sampling the resident size whenever a pose is counted;
// joins and gathers the figures.
// `files` as for a session (tiles_dir: where evicted tiles go).
PipelineFigures run_pipeline(daemon::Pipeline& pipeline, const RunHooks& hooks = {},
                             const daemon::SessionFiles& files = {});

// Resident growth, from the first sample at or after `from_fraction` of the
// poses (when the local map has filled) to the last sample.
struct MemoryGrowth {
  std::uint64_t from_pose = 0;
  double from_mb = 0.0;
  double end_mb = 0.0;
  double max_mb = 0.0;  // the largest sample from from_pose on
  // malloc's bytes in use at the first heap sample from from_pose on and at
  // the end (< 0: not known): resident growth beyond theirs is the allocator's.
  double heap_from_mb = -1.0;
  double heap_end_mb = -1.0;
  double map_from_mb = 0.0;  // the tiled map's own figure, at from_pose and at the end
  double map_end_mb = 0.0;
  // The largest sample of resident size less the map's tiles (issue #26's
  // figure: what aditd holds beyond the map it has built), from from_pose on.
  double max_beyond_map_mb = 0.0;
  double percent() const { return from_mb > 0.0 ? 100.0 * (end_mb - from_mb) / from_mb : 0.0; }
};
std::optional<MemoryGrowth> memory_growth(const std::vector<MemorySample>& samples, double from_fraction);

// The figures as JSON (what --json prints) and as lines for people.
nlohmann::json figures_json(const PipelineFigures& figures, double memory_from_fraction);
std::string figures_text(const PipelineFigures& figures, double memory_from_fraction);

}  // namespace adit::tools
