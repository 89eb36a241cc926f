#pragma once
// The client side of the tablet protocol (docs/PROTOCOL.md), shared by the
// `adit` status/watch/start/stop/sessions/download commands: one LCM socket,
// one payload, typed waits with timeouts.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "adit/command_ack_t.hpp"
#include "adit/frame_t.hpp"
#include "adit/graph_path_t.hpp"
#include "adit/loop_status_t.hpp"
#include "adit/grid_patch_t.hpp"
#include "adit/pose_t.hpp"
#include "adit/protocol/tile_assembler.hpp"
#include "adit/status_t.hpp"
#include "adit/tile_index_t.hpp"
#include "adit/tile_segment_t.hpp"

namespace adit::tools {

struct ClientOptions {
  std::string lcm_url;
  std::string payload_id;
  double timeout_s = 5;
  // A key file (`adit keygen`): every command is signed with its first key.
  std::string key_file;
};

// frame_t's transform, map <- odometry; identity for a default-constructed
// frame_t (none received: its quaternion is zero), a non-unit quaternion or
// a position that is not finite.
Eigen::Isometry3d map_from_odometry(const frame_t& frame);
// The same for the tiles, map <- tiles: schema 2's own transform (the tiles
// follow the pose graph with map.loops_move_map), schema 1's map <- odometry.
Eigen::Isometry3d map_from_tiles(const frame_t& frame);
// A downloaded map's points placed as its session's `frame` places the tiles
// (the prior map's frame, or gravity's level, as the session's own map files:
// decisions 049, 054, 060); false when that moved nothing (no frame, or identity).
bool place_downloaded_points(std::vector<protocol::MapPoint>& points, const std::optional<frame_t>& frame);

class LcmClient {
 public:
  // Throws InputError for a bad payload id or key file and when LCM fails.
  explicit LcmClient(ClientOptions options);
  ~LcmClient();

  // Sends `verb` and waits for its ack, resending the same bytes (same request
  // id, time and tag) every 250 ms: the daemon answers replays without
  // executing them again. Signed when a key file was given.
  std::optional<command_ack_t> command(const std::string& verb, const std::vector<std::string>& args = {});
  // Milliseconds from the last send of the last command() to its ack (the
  // daemon's answer time plus the network's; a retry restarts the clock).
  double last_round_trip_ms() const;

  // Everything a live view follows; an empty handler is not subscribed.
  struct FollowHandlers {
    std::function<void(const pose_t&)> pose;
    std::function<void(const status_t&)> status;
    std::function<void(const tile_index_t&)> tile_index;
    std::function<void(const tile_segment_t&)> tile_segment;
    std::function<void(const grid_patch_t&)> grid_patch;
    std::function<void(const frame_t&)> frame;
    std::function<void(const graph_path_t&)> graph_path;
    std::function<void(const loop_status_t&)> loop_status;
  };
  // Calls the handlers for every message until `until` returns true (checked
  // at least every 50 ms).
  void follow(const FollowHandlers& handlers, const std::function<bool()>& until);
  // Publishes one tile_request_t for `missing` of `session` (at most 3000
  // entries are sent), with the full index when `want_index`; returns its id.
  std::int64_t request_tiles(const std::string& session, const std::vector<protocol::MissingSegment>& missing,
                             bool want_index);

  struct DownloadResult {
    bool ok = false;
    std::string error;
    std::size_t requests = 0;
    std::optional<frame_t> frame;  // the session's, when the daemon sent one (its current or last session)
  };
  // Fetches the tile index and every tile of `session` ("" = the current one)
  // into `tiles`, re-requesting what is missing until complete or no progress
  // for the timeout, and the session's frame_t (waiting up to one status
  // period for it). `progress(have, wanted)` is called as chunks arrive.
  DownloadResult download(const std::string& session, protocol::TileAssembler& tiles,
                          const std::function<void(std::size_t, std::size_t)>& progress);

  struct FileResult {
    bool ok = false;
    std::string error;
    std::string session;  // the session answered for (the daemon's last when none was named)
    std::string bytes;
    std::size_t requests = 0;
  };
  // Fetches one product file of a stored session (file_request_t; `path` as
  // protocol::product_path_problem() accepts, "products/" for the list),
  // asking again for the chunks lost until complete or no progress for the timeout.
  FileResult fetch_file(const std::string& session, const std::string& path);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace adit::tools
