#pragma once
// adit console: the live side. One thread follows the payload's LCM channels
// as the tablet would (tools/src/lcm_client.cpp): poses, status, the tile
// index and the tile segments of the current session, asking for what it
// lacks like `adit download` does. It keeps the latest status, the path and
// the map (protocol::TileAssembler), the live 2D grid (protocol::GridMosaic),
// and publishes what changed as events:
//   pose     every pose, with the console's receive time (for the latency)
//   status   every status (2 Hz), with the session's latest loop_status_t
//            as "loops" while its loop closure runs
//   tiles    the tiles completed at a new version, at most every 250 ms
//   grid     the grid changed (its version), at most every 500 ms
//   session  the payload's session changed (the browser clears its map)
//   graph_path  the pose graph placed the path anew (a loop closed): its
//            keyframes, in the tiles' frame; the path kept from the poses
//            starts at its newest keyframe from then on
//   link     the payload stopped answering (no status for 2 s) or came back

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "adit/protocol/grid_mosaic.hpp"
#include "adit/protocol/tile_assembler.hpp"
#include "console_events.hpp"
#include "console_grid.hpp"
#include "lcm_client.hpp"

namespace adit::tools::console {

nlohmann::json status_json(const status_t& s);
nlohmann::json pose_json(const pose_t& p, std::int64_t received_ms);
// frame_t for the page: map <- odometry as {"source", "p": [x y z], "q": [w x y z]},
// the page's path and pose through it; map <- tiles as "tp", "tq", the tiles
// and the grid through it.
nlohmann::json frame_json(const frame_t& f);
// graph_path_t for the page: {"session", "rev", "utime" (the newest
// keyframe's, µs), "n_keyframes", "points": [[x y z], ...]}.
nlohmann::json graph_path_json(const graph_path_t& g);
// loop_status_t for the page: {"session", "keyframes", "candidates",
// "accepted", "rejected", "last_loop_us" (wall clock, 0: none yet),
// "correction_m", "correction_deg", "moves_map"}.
nlohmann::json loops_json(const loop_status_t& l);

// A tile's points for a browser: segments `from` .. n-1 at `version`, every
// `every`-th point (x y z as float32, little-endian, per segment a uint32
// count first).
struct TileBytes {
  std::int32_t version = 0;
  std::int32_t from = 0;
  std::int32_t n_segments = 0;
  std::int64_t n_points = 0;  // the tile's, before decimation
  std::string body;
};

class LiveFeed {
 public:
  // The map's segments are kept in a spill file in `spill_dir` (in RAM when empty).
  LiveFeed(ClientOptions options, EventHub& hub, const std::filesystem::path& spill_dir = {});
  ~LiveFeed();
  LiveFeed(const LiveFeed&) = delete;
  LiveFeed& operator=(const LiveFeed&) = delete;

  // The whole current state: link, status, last pose, path, tile versions.
  nlohmann::json snapshot() const;
  // Tile `id` for a browser that holds it at `held_version` (0 = nothing):
  // only the segments changed since when the console knows them.
  std::optional<TileBytes> tile(std::int64_t id, std::int32_t held_version, int every) const;
  // The current session's grid as a PNG (encoded once per version, when a
  // browser asks), or null when no patch is held.
  std::shared_ptr<const GridBytes> grid() const;
  // The grid's blocks for GET /api/grid/blocks: {session, v, patches,
  // resolution, block_cells, origin_x, origin_y, width, height (the whole
  // grid's, as GET /api/grid), blocks: [[x, y, v], ...]}; null when no patch
  // is held.
  std::optional<nlohmann::json> grid_blocks() const;
  // Block (x, y) as a PNG (encoded once per block version, when a browser
  // asks), or null when the grid holds no patch in it.
  std::shared_ptr<const GridBytes> grid_block(std::int32_t x, std::int32_t y) const;

 private:
  void run();
  void on_pose(const pose_t& p);
  void on_status(const status_t& s);
  void on_frame(const frame_t& f);
  void on_graph_path(const graph_path_t& g);
  void on_loop_status(const loop_status_t& l);
  void on_index(const tile_index_t& m);
  void on_segment(const tile_segment_t& m);
  void on_grid(const grid_patch_t& m);
  void tick();  // requests, throttled tile and grid events, the link watch
  void switch_session(const std::string& session);  // under mutex_

  ClientOptions options_;
  EventHub& hub_;
  std::atomic<bool> stop_{false};

  mutable std::mutex mutex_;
  std::string session_;
  std::optional<nlohmann::json> status_;
  std::optional<nlohmann::json> pose_;
  std::optional<nlohmann::json> frame_;  // the session's, once its frame_t came
  std::optional<nlohmann::json> loops_;  // the session's latest loop_status_t
  // The path from the poses: a point per kPathStepM travelled, with its
  // pose's utime; from the graph's newest keyframe on once a graph path came.
  struct PathPoint {
    std::array<float, 3> at{};
    std::int64_t utime = 0;
  };
  std::vector<PathPoint> path_;
  std::optional<nlohmann::json> graph_path_;  // the session's latest graph_path_t
  std::int32_t graph_revision_ = 0;           // its revision
  std::int64_t graph_utime_ = 0;              // its newest keyframe's time
  std::shared_ptr<protocol::FrameSpill> spill_;  // the map's segments on disk (null: in RAM)
  protocol::TileAssembler tiles_;
  // Per tile, the completions seen: (version before, version, first segment replaced).
  struct Change {
    std::int32_t before = 0, version = 0, from = 0;
  };
  std::map<std::int64_t, std::vector<Change>> changes_;
  std::map<std::int64_t, std::int32_t> pending_event_;  // tile -> version completed, not yet announced
  std::int64_t last_status_ms_ = 0;
  std::int64_t last_segment_ms_ = 0;
  std::int64_t last_request_ms_ = 0;
  std::int64_t last_tiles_event_ms_ = 0;
  bool index_received_ = false;  // the full index of session_ came (else asked for again every 2 s)
  bool link_up_ = false;

  protocol::GridMosaic grid_;
  // The grid's version is grid_.version_sum(): a browser that reconnects to
  // a restarted console, which holds fewer patches at first, fetches the grid
  // again only once that number passes the one it holds.
  bool grid_changed_ = false;  // not yet announced
  std::int64_t last_grid_event_ms_ = 0;
  mutable std::shared_ptr<const GridBytes> grid_png_;  // the last one encoded
  mutable std::map<std::pair<std::int32_t, std::int32_t>, std::shared_ptr<const GridBytes>> block_pngs_;  // each block's last

  std::unique_ptr<LcmClient> client_;  // used by the feed's thread only (request_tiles)
  std::thread thread_;
};

}  // namespace adit::tools::console
