#pragma once
// The daemon's side of the tablet protocol (docs/PROTOCOL.md): one thread that
// owns the LCM socket, publishes poses, status and map tiles handed over by
// the pipeline through lock-free queues, answers tile requests with only the
// missing chunks, and acknowledges commands through the session state machine.
// LCM is confined to this file's implementation, the IMU-rate pose's sender
// (imu_pose_publisher.hpp, which needs no queue) and the `adit` client.

#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "adit/protocol/localise_hint.hpp"
#include "adit/protocol/map_point.hpp"
#include "adit/protocol/session_state.hpp"
#include "adit/protocol/tile_codec.hpp"
#include "adit/daemon/grid_publisher.hpp"
#include "adit/daemon/loop_status.hpp"
#include "adit/daemon/map_frame.hpp"
#include "adit/daemon/tile_store.hpp"

namespace adit::slam {
class CorrectionTrack;
}

namespace adit::daemon {

struct PoseSample {
  std::int64_t utime = 0;
  std::array<double, 3> position{};
  std::array<double, 4> orientation{1, 0, 0, 0};  // w, x, y, z
  std::array<double, 36> covariance{};
  std::int32_t flags = 0;  // pose_t.FLAG_*
};

struct SensorHealth {
  std::string name;
  float packet_rate_hz = 0;
  std::int64_t packets_dropped = 0;
  std::int64_t last_seen_utime = 0;
  float time_offset_s = 0;
};

struct ThreadLoad {
  std::string name;
  float load = 0;
  std::int32_t queue_depth = 0;
  std::int32_t queue_capacity = 0;
};

// What the daemon knows about its health; the endpoint adds state, session
// and map size.
struct StatusSample {
  std::int64_t utime = 0;
  std::vector<SensorHealth> sensors;
  std::vector<ThreadLoad> threads;
  std::int64_t disk_free_bytes = 0;
  std::string fault;
  // A running session's frame; none between sessions (the endpoint keeps
  // sending the last session's, so a client still draws its map in place).
  std::optional<MapFrame> frame;
  // The loop closure's latest correction while it moves the map: its
  // keyframes go out as graph_path_t when it changes and every 5 s after
  // (kept, as the frame, once the session ended).
  std::shared_ptr<const slam::CorrectionTrack> graph;
  // The loop closure's progress, sent as loop_status_t; none when the
  // session runs no loop closure (or between sessions).
  std::optional<LoopStatus> loops;
};

// New content of one tile (after voxel downsampling): what it gained, or all of it.
struct TileUpdate {
  std::int64_t utime = 0;
  protocol::TileKey key;
  std::vector<protocol::MapPoint> points;
  // `points` are the tile's from this one on; those before it are the ones
  // of its previous updates (0: the whole tile).
  std::size_t first_point = 0;
};

// What commands make the daemon do; each runs on the endpoint thread and must
// return quickly (the ack goes out after it, within 100 ms of the command).
struct SessionHooks {
  std::function<std::string()> start;  // begins a session, returns its id
  std::function<void()> stop;          // begins the flush; call session_stopped() when done
  std::function<std::vector<std::string>()> sessions;  // ids of sessions on disk
  // EXPORT: writes the exports of the session, returns what was written.
  std::function<std::string(const std::string& session, const std::vector<std::string>& args)> export_map;
  // A download of a stored session (not the one in memory): fills `into`
  // from its folder; returns "" or why not. Called only while IDLE.
  std::function<std::string(const std::string& session, TileStore& into)> load_tiles;
  // The frame of a stored session whose tiles load_tiles filled (its tiles
  // and poses in its map frame), sent as frame_t with each answer to a
  // request for them; nullopt (or unset): the session's own frame, none sent.
  std::function<std::optional<MapFrame>(const std::string& session)> stored_frame;
  // The folder of a session just started: the tile stream keeps its segments
  // in a file there rather than in RAM. Empty (or unset): in RAM.
  std::function<std::filesystem::path(const std::string& session)> session_folder;
  // HINT: hands the running session's search against its prior map an
  // approximate start; returns "" or why it was not taken.
  std::function<std::string(const protocol::LocaliseHint& hint)> hint;
};

struct EndpointOptions {
  std::string lcm_url;
  std::string payload_id;
  protocol::TileParams tiles;
  double tile_period_s = 1.0;          // changed tiles go out at most this often
  double chunk_bytes_per_s = 4.0e6;    // pacing of tile chunks (broadcast and answers)
  double grid_period_s = 1.0;          // changed live-grid patches go out at most this often
  double grid_refresh_s = 10.0;        // every patch again within this
  std::size_t queue_capacity = 256;    // per hand-off queue
  std::size_t command_window = 1024;   // request ids remembered for replays
  // Command authentication (docs/COMMAND-AUTH.md): a key file readable only by
  // the service; empty = commands are not authenticated. The file is checked
  // for changes every `key_check_period_s` and re-read (key rotation without
  // a restart); a file that has become unreadable or bad keeps the old keys.
  std::filesystem::path key_file;
  double command_window_s = 30;        // a signed command's time may differ this much from ours
  double key_check_period_s = 1.0;
  // Test hook: this fraction of tile chunks is silently not sent.
  double drop_chunk_fraction = 0;
  std::uint32_t drop_seed = 1;
};

struct EndpointCounters {
  std::atomic<std::uint64_t> poses_published{0};
  std::atomic<std::uint64_t> poses_dropped{0};  // hand-off queue full
  std::atomic<std::uint64_t> status_published{0};
  std::atomic<std::uint64_t> frames_published{0};
  std::atomic<std::uint64_t> graph_paths_published{0};
  std::atomic<std::uint64_t> loop_statuses_published{0};
  std::atomic<std::uint64_t> status_dropped{0};
  std::atomic<std::uint64_t> tiles_dropped{0};
  std::atomic<std::uint64_t> chunks_published{0};
  std::atomic<std::uint64_t> chunks_dropped_by_hook{0};
  std::atomic<std::uint64_t> chunk_bytes_published{0};
  std::atomic<std::uint64_t> index_published{0};
  std::atomic<std::uint64_t> segment_read_errors{0};  // tile segments whose file could not be read
  std::atomic<std::uint64_t> grid_patches_published{0};  // live-grid patches, changed and refreshed
  std::atomic<std::uint64_t> grid_bytes_published{0};
  std::atomic<std::uint64_t> grid_patches_dropped{0};    // hand-off queue full
  std::atomic<std::uint64_t> file_requests{0};  // product files (file_request_t)
  std::atomic<std::uint64_t> file_requests_malformed{0};
  std::atomic<std::uint64_t> file_chunks_published{0};
  std::atomic<std::uint64_t> commands_executed{0};
  std::atomic<std::uint64_t> commands_rejected{0};
  std::atomic<std::uint64_t> commands_replayed{0};
  std::atomic<std::uint64_t> commands_malformed{0};
  // Rejections by reason (each also in commands_rejected); see GateCounts.
  std::atomic<std::uint64_t> commands_unsigned{0};
  std::atomic<std::uint64_t> commands_bad_tag{0};
  std::atomic<std::uint64_t> commands_stale{0};
  std::atomic<std::uint64_t> commands_replay_rejected{0};
  std::atomic<std::uint64_t> commands_other_payload{0};
  std::atomic<bool> commands_authenticated{false};  // a key file is in force
  std::atomic<std::uint64_t> key_reloads{0};        // key file re-read after a change
  std::atomic<std::uint64_t> key_reload_errors{0};  // a changed key file refused (old keys kept)
  std::atomic<std::uint64_t> tile_requests{0};
  std::atomic<std::uint64_t> tile_requests_malformed{0};
  std::atomic<std::uint64_t> largest_message_bytes{0};
};

class LcmEndpoint {
 public:
  // Throws std::runtime_error when LCM cannot open `options.lcm_url`, and
  // adit::InputError when the payload id is unusable.
  LcmEndpoint(EndpointOptions options, SessionHooks hooks);
  ~LcmEndpoint();
  LcmEndpoint(const LcmEndpoint&) = delete;
  LcmEndpoint& operator=(const LcmEndpoint&) = delete;

  // Hand-offs: each may be called from one producer thread; false (and a
  // counted drop) when the publisher is behind.
  bool publish_pose(const PoseSample& pose);
  bool publish_status(StatusSample&& status);
  bool publish_tile(TileUpdate&& tile);
  // Any thread: points of tiles handed to publish_tile that the endpoint's
  // thread has not taken yet.
  std::uint64_t tile_points_waiting() const;
  bool publish_grid(GridPatchUpdate&& patch);

  // The daemon finished flushing the stopping session (STOPPING -> IDLE).
  void session_stopped();
  // The GPIO button: starts when idle, stops when mapping.
  void button_pressed();
  // The daemon's own start (session.autostart) and stop (a replay ran out):
  // the same transitions as the tablet's commands, without an ack.
  void start_session();
  void stop_session();

  protocol::SessionState state() const;
  const EndpointCounters& counters() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace adit::daemon
