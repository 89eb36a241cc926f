#pragma once
// Mapping sessions: IDLE → MAPPING → STOPPING → IDLE (docs/PROTOCOL.md).
//
// start() makes the session folder in <state_dir>/sessions/<id>/ and starts a
// pipeline that writes the trajectory as it goes, records the raw packets when
// configured, and hands poses and map tiles to the tablet endpoint. A stop
// (asked for, or the end of a replayed recording) ends the source, lets every
// stage drain, and then, on a thread of its own so that the supervisor keeps
// petting the watchdog, writes the session's files:
//   trajectory.tum   body poses in the map frame (TUM), written live
//   map.ply|pcd|las  the map (session.exports), from the same tiles the tablet gets
//   tiles/<id>.adt   each tile's encoded blob (protocol/tile_codec.hpp), for downloads later;
//                    written during the session for tiles the sensor has left (eviction)
//   keyframes.tum    keyframe poses; keyframes/<stamp_ns>.ply the scans of older keyframes
//   summary.json     counts, timings, files; config.yaml the effective configuration
//   lidar.pcap       raw packets, when session.record_lidar is true
//   products/        after summary.json, on a low-priority thread of its own
//                    (session.products; products_worker.hpp): occupancy,
//                    grid, top view, cross-sections, targets
//   journal.adj      while mapping (session.journal): the map as it is made,
//                    durable within session.journal_sync_s; removed once
//                    summary.json is on the disk. A folder with a journal and
//                    no summary was cut short (a crash, a pulled battery): the
//                    constructor starts rebuilding each such session on a
//                    background thread (session_recovery.hpp).

#include <atomic>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "adit/protocol/localise_hint.hpp"
#include "adit/config/config.hpp"
#include "adit/daemon/heartbeat.hpp"
#include "adit/daemon/lcm_endpoint.hpp"
#include "adit/daemon/pipeline.hpp"

namespace adit::daemon {

// Converts an odometry result to the pose the tablet gets (flags: pose_t.FLAG_*).
PoseSample pose_sample_of(const slam::OdometryResult& result);

class ProductsWorker;

// What the listing says of a stored session beside its id: "" or, each with
// a leading space, "recovered" (rebuilt from its journal after a crash) and
// "joined to <id>" (its joined.json: `adit join` placed it into that
// session's map).
std::string session_notes(const std::filesystem::path& dir);

class Sessions {
 public:
  // `publish_pose`/`publish_tile` may be empty (no endpoint); `ended` runs on
  // the finishing thread once a session's files are written.
  struct Outputs {
    std::function<void(const PoseSample&)> pose;
    PipelineSinks::ImuPoseSink imu_pose;  // the IMU source's thread
    std::function<bool(TileUpdate&&)> tile;  // true when taken
    std::function<std::uint64_t()> tile_backlog;  // points handed to `tile` not yet taken (PipelineSinks)
    std::function<void(GridPatchUpdate&&)> grid;  // the mapping thread
    std::function<void(const std::string& session)> ended;
  };

  // Builds the first session's pipeline at once, so that a START is answered
  // within milliseconds and a bad source (a missing pcap, a busy port) stops
  // aditd at launch: throws adit::InputError naming it.
  Sessions(const config::Config& config, Outputs outputs);
  ~Sessions();
  Sessions(const Sessions&) = delete;
  Sessions& operator=(const Sessions&) = delete;

  // Starts a session and returns its id. Throws adit::InputError (a bad
  // source: named) or std::runtime_error when it cannot; nothing is left running then.
  std::string start();
  // Asks the running session to stop; poll() does the work.
  void request_stop();
  // Main thread, a few times a second: begins finishing a session that was
  // asked to stop or whose replay has ended; reaps a finished one. Returns
  // true when the running session's source ended by itself (the caller moves
  // the state machine to STOPPING).
  bool poll();
  // Blocks until no session runs and every file is written (shutdown).
  void stop_and_wait();

  bool running() const;  // a pipeline exists (mapping or being finished)
  // Sessions on disk, oldest first: "<id>" and its session_notes().
  std::vector<std::string> list() const;
  std::filesystem::path folder(const std::string& id) const;
  // Fills `into` with a stored session's tiles: tiles_graph/*.adt when loop
  // closure moved its map (as the live tiles were at the end), else
  // tiles/*.adt; "" or why not. `id` comes from the network: only a plain
  // session name is accepted.
  std::string load_tiles(const std::string& id, TileStore& into) const;
  // The frame those tiles are in (stored_session_frame); nullopt in the
  // session's own frame, or when its frame files are unreadable (logged).
  std::optional<MapFrame> stored_frame(const std::string& id) const;
  // HINT: the running session's search against its prior map narrowed to
  // `hint` (prior_localiser.hpp); "" or why not (no session, no prior, anchored).
  std::string hint(const protocol::LocaliseHint& hint);
  // What the status message says about the running session (empty when idle).
  StatusSample status_sample();
  // Heartbeats of the running session's threads (empty when idle).
  std::vector<const Heartbeat*> heartbeats() const;
  std::vector<std::string> take_warnings();
  // Why the last start() failed (once), or null: aditd --once exits with it.
  std::exception_ptr take_start_failure();

 private:
  std::string session_faults(const PipelineStats& stats, std::uint64_t datagrams, const std::string& imu_source,
                             std::int64_t disk_free);
  std::string start_locked();
  std::unique_ptr<Pipeline> build_pipeline() const;
  void finish(std::unique_ptr<Pipeline> pipeline, std::string id, std::filesystem::path dir);
  void recover_interrupted();  // the recovery thread's body

  config::Config config_;
  Outputs outputs_;
  std::filesystem::path root_;
  mutable std::mutex mutex_;  // control only: start, stop, poll; never a pipeline thread
  std::unique_ptr<Pipeline> pipeline_;
  std::unique_ptr<Pipeline> standby_;  // built ahead of the next session (allocation takes ~0.2 s)
  std::string id_;
  std::filesystem::path dir_;
  std::atomic<bool> stop_requested_{false};
  bool end_reported_ = false;  // poll() said the source ended (once per session)
  std::thread finisher_;
  std::atomic<bool> finishing_{false};
  std::vector<std::string> warnings_;
  std::exception_ptr start_failure_;
  // Status: packet rate and thread load from differences between samples.
  std::int64_t last_sample_ns_ = 0;
  std::uint64_t last_datagrams_ = 0;
  std::vector<double> last_cpu_s_;
  // Sessions cut short, rebuilt at start-up off the main thread; what the
  // status says about them while idle (until the next session starts).
  std::thread recoverer_;
  std::string recovery_notice_;  // under mutex_
  std::unique_ptr<ProductsWorker> products_;  // null when session.products is off
};

}  // namespace adit::daemon
