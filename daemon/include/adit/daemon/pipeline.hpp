#pragma once
// The packet-to-pose pipeline of aditd and `adit replay`: it builds the
// stages, joins them by preallocated lock-free hand-offs (handoff.hpp) and
// runs them, one thread each; it holds no stage logic itself.
//
//   LidarSource ─scans→ OdometryStage ─poses→ OutputStage → pose sink, trajectory
//   (receiver,           (odometry)    └─scans+poses→ MappingStage → tile sink, map
//    assembly)               ↑ wheels, accelerometer
//                        CanFeed (can)
//
// Each stage's header says what comes in, what goes out and what it may not
// do. After start-up no stage before mapping allocates per packet or per scan
// (the map grows by nature).

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "adit/config/config.hpp"
#include "adit/daemon/heartbeat.hpp"
#include "adit/daemon/pipeline_items.hpp"
#include "adit/daemon/pipeline_stats.hpp"
#include "adit/daemon/tile_spill.hpp"
#include "adit/slam/keyframes.hpp"
#include "adit/slam/odometry.hpp"
#include "adit/slam/tiled_map.hpp"

namespace adit::daemon {

class ImuPoseFeed;
class LoopClosureStage;
class JournalWriter;
class PriorLocaliser;
struct CanFeedStats;

struct PipelineOptions {
  std::filesystem::path trajectory_file;  // TUM, written as poses arrive; empty = none
  // TUM: each mapped scan's pose as the map placed it (with map.refine, the
  // refined pose; the published one is the odometry's); empty = none.
  std::filesystem::path map_trajectory_file;
  std::filesystem::path record_file;      // raw LiDAR packets as pcap; empty = none
  double replay_speed = -1.0;             // pcap/scan_dir: overrides lidar.replay_speed when ≥ 0
  slam::OdometryConfig odometry;          // range limits come from the lidar section
  bool mapping = true;                    // run the mapping thread (config `map` section)
  // A stored session's map (map.ply) to localise against and follow, prepared
  // as a prior when the pipeline is built (prior_map.previous_session); used
  // only without prior_map.dir. Empty: none.
  std::filesystem::path prior_session_map;
  PipelineSinks sinks;
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
  // The session journal (journal_writer.hpp): map poses, tile points and
  // keyframes appended as they are made, so a crash loses at most ~1 s of
  // the map; empty = none. `journal_header` is its header record (JSON).
  std::filesystem::path journal_file;
  std::string journal_header;
  // Where the odometry frame's place in the prior map is written once aditd
  // localised against it (prior_map.dir; prior_localiser.hpp); empty = not written.
  std::filesystem::path prior_frame_file;
  // Where gravity's level is written from the odometry's first up, again as it turns
  // (session_frame.hpp); empty = not written, the exports stay in the odometry frame.
  std::filesystem::path level_frame_file;
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
  // Stops the raw recording (low disk space); the pipeline goes on. Any thread.
  void stop_recording(RecordingStop why);
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
  // Any thread: gravity's level as the mapping thread last kept it
  // (MappingStage::level); nullopt before the odometry had an up, or without one.
  std::optional<Eigen::Isometry3d> level() const;
  // Any thread: the map's refinement of the odometry at the last scan mapped
  // (MappingStage::refinement); identity without a mapping stage.
  Eigen::Isometry3d refinement() const;
  // The live 2D grid (grid.enabled), complete after join(); null without it.
  const slam::LiveGrid* grid() const;
  // The loop-closure stage (map.loop_closure), complete after join(); null without it.
  const LoopClosureStage* loop_closure() const;
  // The session journal's writer (SessionFiles::journal_file), closed after join(); null without it.
  const JournalWriter* journal() const;
  // The CAN thread's counters (bus health, frames); null without a CAN feed.
  const CanFeedStats* can_stats() const;
  // The IMU-rate pose (its count, and its latencies after join()); null without an IMU or with imu.pose_horizon_s 0.
  const ImuPoseFeed* imu_poses() const;
  // Localisation against the prior map (prior_map.dir); null without a usable prior.
  const PriorLocaliser* prior_localiser() const;
  PriorLocaliser* prior_localiser();  // for a hint (HINT)
  // Where the prior came from (prior_map.dir or the stored session's map); "" without one.
  const std::string& prior_source() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace adit::daemon
