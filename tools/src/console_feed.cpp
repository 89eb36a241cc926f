#include "console_feed.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "adit/common/clock.hpp"
#include "adit/common/log.hpp"
#include "adit/grid_patch_t.hpp"
#include "adit/protocol/session_state.hpp"

namespace adit::tools::console {
namespace {

constexpr std::int64_t kLinkSilentMs = 2000;    // no status for this long: the payload stopped answering
constexpr std::int64_t kQuietBeforeAskMs = 300;  // as `adit download`: ask once the stream is quiet
constexpr std::int64_t kAskEveryMs = 500;
constexpr std::int64_t kAskIndexEveryMs = 2000;  // until the full index comes (a payload down at first)
constexpr std::int64_t kTilesEventEveryMs = 250;
constexpr std::int64_t kGridEventEveryMs = 500;  // the payload sends changed patches at most once a second
constexpr double kPathStepM = 0.05;       // the path keeps a point per 5 cm travelled
constexpr std::size_t kPathMax = 20000;   // then every other one is dropped
constexpr std::size_t kChangesKept = 32;  // completions remembered per tile

std::int64_t now_ms() { return realtime_us() / 1000; }

// The protocol's name of a status_t/command_ack_t state.
std::string state_name(int state) {
  return std::string(protocol::state_name(static_cast<protocol::SessionState>(state)));
}

void append_f32(std::string& out, float v) {
  char b[sizeof v];
  std::memcpy(b, &v, sizeof v);
  out.append(b, sizeof v);
}
void append_u32(std::string& out, std::uint32_t v) {
  char b[sizeof v];
  std::memcpy(b, &v, sizeof v);
  out.append(b, sizeof v);
}

}  // namespace

nlohmann::json status_json(const status_t& s) {
  nlohmann::json sensors = nlohmann::json::array();
  for (const auto& h : s.sensors)
    sensors.push_back({{"name", h.name},
                       {"rate_hz", h.packet_rate_hz},
                       {"dropped", h.packets_dropped},
                       {"last_seen_us", h.last_seen_utime},
                       {"offset_s", h.time_offset_s}});
  nlohmann::json threads = nlohmann::json::array();
  for (const auto& t : s.threads)
    threads.push_back(
        {{"name", t.name}, {"load", t.load}, {"depth", t.queue_depth}, {"capacity", t.queue_capacity}});
  return {{"utime", s.utime},      {"payload", s.payload_id},   {"state", state_name(s.state)},
          {"session", s.session_id}, {"sensors", sensors},      {"threads", threads},
          {"disk_free", s.disk_free_bytes}, {"map_points", s.map_points}, {"map_tiles", s.map_tiles},
          {"fault", s.fault}};
}

nlohmann::json pose_json(const pose_t& p, std::int64_t received_ms) {
  return {{"seq", p.seq},
          {"utime", p.utime},
          {"rx", received_ms},
          {"session", p.session_id},
          {"p", {p.position[0], p.position[1], p.position[2]}},
          {"q", {p.orientation[0], p.orientation[1], p.orientation[2], p.orientation[3]}},
          {"valid", (p.flags & pose_t::FLAG_VALID) != 0},
          {"degenerate", (p.flags & pose_t::FLAG_DEGENERATE) != 0},
          {"held", (p.flags & pose_t::FLAG_HELD) != 0},
          {"lost", (p.flags & pose_t::FLAG_LOST) != 0},
          {"relocalised", (p.flags & pose_t::FLAG_RELOCALISED) != 0}};
}

nlohmann::json frame_json(const frame_t& f) {
  return {{"session", f.session_id},
          {"source", f.source == frame_t::SOURCE_PRIOR_MAP ? "prior_map"
                     : f.source == frame_t::SOURCE_LOOPS  ? "loops"
                     : f.source == frame_t::SOURCE_LEVEL  ? "level"
                                                          : "odometry"},
          {"p", {f.position[0], f.position[1], f.position[2]}},
          {"q", {f.orientation[0], f.orientation[1], f.orientation[2], f.orientation[3]}},
          {"tp", {f.tiles_position[0], f.tiles_position[1], f.tiles_position[2]}},
          {"tq", {f.tiles_orientation[0], f.tiles_orientation[1], f.tiles_orientation[2], f.tiles_orientation[3]}}};
}

nlohmann::json graph_path_json(const graph_path_t& g) {
  nlohmann::json points = nlohmann::json::array();
  const auto mm = [](float v) { return std::round(static_cast<double>(v) * 1000.0) / 1000.0; };  // shorter JSON
  for (const auto& p : g.positions) points.push_back({mm(p[0]), mm(p[1]), mm(p[2])});
  return {{"session", g.session_id},
          {"rev", g.revision},
          {"utime", g.utime},
          {"n_keyframes", g.n_keyframes},
          {"points", std::move(points)}};
}

nlohmann::json loops_json(const loop_status_t& l) {
  return {{"session", l.session_id},
          {"keyframes", l.keyframes},
          {"candidates", l.candidates},
          {"accepted", l.accepted},
          {"rejected", l.rejected},
          {"last_loop_us", l.last_loop_utime},
          {"correction_m", l.correction_m},
          {"correction_deg", l.correction_deg},
          {"moves_map", l.moves_map != 0}};
}

LiveFeed::LiveFeed(ClientOptions options, EventHub& hub, const std::filesystem::path& spill_dir)
    : options_(std::move(options)),
      hub_(hub),
      spill_(spill_dir.empty() ? nullptr : protocol::FrameSpill::open(spill_dir)),
      tiles_(spill_),
      client_(std::make_unique<LcmClient>(options_)) {
  last_status_ms_ = now_ms();  // silent since the console started, until a status arrives
  thread_ = std::thread([this] { run(); });
}

LiveFeed::~LiveFeed() {
  stop_ = true;
  thread_.join();
}

void LiveFeed::run() {
  client_->follow({.pose = [this](const pose_t& p) { on_pose(p); },
                   .status = [this](const status_t& s) { on_status(s); },
                   .tile_index = [this](const tile_index_t& m) { on_index(m); },
                   .tile_segment = [this](const tile_segment_t& m) { on_segment(m); },
                   .grid_patch = [this](const grid_patch_t& m) { on_grid(m); },
                   .frame = [this](const frame_t& m) { on_frame(m); },
                   .graph_path = [this](const graph_path_t& m) { on_graph_path(m); },
                   .loop_status = [this](const loop_status_t& m) { on_loop_status(m); }},
                  [this] {
                    tick();
                    return stop_.load();
                  });
}

void LiveFeed::switch_session(const std::string& session) {
  if (session == session_) return;
  session_ = session;
  tiles_ = protocol::TileAssembler(spill_);  // the last session's frames freed on disk
  changes_.clear();
  pending_event_.clear();
  path_.clear();
  graph_path_.reset();
  graph_revision_ = 0;
  graph_utime_ = 0;
  index_received_ = false;
  grid_ = {};
  grid_changed_ = false;
  grid_png_.reset();
  block_pngs_.clear();
  frame_.reset();
  loops_.reset();
  hub_.publish("session", nlohmann::json{{"session", session}}.dump());
}

void LiveFeed::on_pose(const pose_t& p) {
  const std::int64_t rx = now_ms();
  nlohmann::json j = pose_json(p, rx);
  {
    const std::lock_guard lock(mutex_);
    if (!p.session_id.empty()) switch_session(p.session_id);
    if (p.flags & pose_t::FLAG_VALID) {
      const std::array<float, 3> at{static_cast<float>(p.position[0]), static_cast<float>(p.position[1]),
                                    static_cast<float>(p.position[2])};
      const auto far = [&](const std::array<float, 3>& last) {
        const float dx = at[0] - last[0], dy = at[1] - last[1], dz = at[2] - last[2];
        return dx * dx + dy * dy + dz * dz >= kPathStepM * kPathStepM;
      };
      if (p.utime >= graph_utime_ && (path_.empty() || far(path_.back().at))) {
        path_.push_back({at, p.utime});
        if (path_.size() > kPathMax) {
          std::vector<PathPoint> halved;
          for (std::size_t i = 0; i < path_.size(); i += 2) halved.push_back(path_[i]);
          path_ = std::move(halved);
        }
      }
    }
    pose_ = j;
  }
  hub_.publish("pose", j.dump());
}

void LiveFeed::on_status(const status_t& s) {
  if (s.payload_id != options_.payload_id) return;
  nlohmann::json j = status_json(s);
  bool came_back = false;
  {
    const std::lock_guard lock(mutex_);
    if (!s.session_id.empty()) switch_session(s.session_id);
    if (loops_) j["loops"] = *loops_;  // this session's (the daemon sends it just before the status)
    status_ = j;
    last_status_ms_ = now_ms();
    came_back = !link_up_;
    link_up_ = true;
  }
  if (came_back) hub_.publish("link", nlohmann::json{{"up", true}}.dump());
  hub_.publish("status", j.dump());
}

// Kept for the next status event, which carries it to the page.
void LiveFeed::on_loop_status(const loop_status_t& l) {
  if (l.payload_id != options_.payload_id || l.session_id.empty()) return;
  nlohmann::json j = loops_json(l);
  const std::lock_guard lock(mutex_);
  switch_session(l.session_id);
  loops_ = std::move(j);
}

// Sent on to the page when it changes (frame_t comes at 2 Hz, changes once a session at most).
void LiveFeed::on_frame(const frame_t& f) {
  if (f.payload_id != options_.payload_id || f.session_id.empty()) return;
  nlohmann::json j = frame_json(f);
  {
    const std::lock_guard lock(mutex_);
    switch_session(f.session_id);
    if (frame_ == j) return;
    frame_ = j;
  }
  hub_.publish("frame", j.dump());
}

// Announced when the graph changed (it comes again every 5 s unchanged). The
// poses' path before its newest keyframe is dropped: the graph's is drawn there.
void LiveFeed::on_graph_path(const graph_path_t& g) {
  if (g.payload_id != options_.payload_id || g.session_id.empty()) return;
  std::string event;
  {
    const std::lock_guard lock(mutex_);
    switch_session(g.session_id);
    if (graph_path_ && g.revision == graph_revision_ && g.utime == graph_utime_) return;
    graph_path_ = graph_path_json(g);
    graph_revision_ = g.revision;
    graph_utime_ = g.utime;
    std::erase_if(path_, [&](const PathPoint& p) { return p.utime < g.utime; });
    event = graph_path_->dump();
  }
  hub_.publish("graph_path", std::move(event));
}

void LiveFeed::on_index(const tile_index_t& m) {
  if (m.payload_id != options_.payload_id || !m.error.empty()) return;
  const std::lock_guard lock(mutex_);
  if (session_.empty()) switch_session(m.session_id);
  if (m.session_id != session_) return;
  if (m.full) index_received_ = true;
  for (std::size_t i = 0; i < m.tile_ids.size(); ++i) tiles_.note_index(m.tile_ids[i], m.versions[i], m.n_chunks[i]);
}

void LiveFeed::on_segment(const tile_segment_t& m) {
  const std::lock_guard lock(mutex_);
  if (session_.empty() || m.session_id != session_) return;
  last_segment_ms_ = now_ms();
  const std::int32_t before = tiles_.held(m.tile_id) ? tiles_.held(m.tile_id)->version : 0;
  if (tiles_.add_segment(m) != protocol::SegmentOutcome::completed) return;
  const auto held = tiles_.held(m.tile_id);
  if (!held) return;
  auto& list = changes_[m.tile_id];
  list.push_back({before, held->version, before == 0 ? 0 : held->replaced_from});
  if (list.size() > kChangesKept) list.erase(list.begin());
  pending_event_[m.tile_id] = held->version;
}

void LiveFeed::on_grid(const grid_patch_t& m) {
  if (m.payload_id != options_.payload_id) return;
  const std::lock_guard lock(mutex_);
  if (session_.empty()) switch_session(m.session_id);
  if (m.session_id != session_) return;
  const std::uint64_t accepted = grid_.counts().accepted;
  if (const std::string problem = grid_.accept(m); !problem.empty()) {
    if (grid_.counts().refused == 1) log::warn("adit console: a grid patch refused (more are not logged): {}", problem);
    return;
  }
  if (grid_.counts().accepted == accepted) return;  // a refresh of a version held
  grid_changed_ = true;
}

void LiveFeed::tick() {
  const std::int64_t now = now_ms();
  bool link_lost = false;
  std::string tiles_event;
  std::string grid_event;
  {
    const std::lock_guard lock(mutex_);
    if (link_up_ && now - last_status_ms_ > kLinkSilentMs) {
      link_up_ = false;
      link_lost = true;
    }
    if (!session_.empty() && now - last_segment_ms_ > kQuietBeforeAskMs && now - last_request_ms_ > kAskEveryMs) {
      const auto missing = tiles_.missing(3000);
      const bool ask_index = !index_received_ && now - last_request_ms_ > kAskIndexEveryMs;
      if (ask_index || !missing.empty()) {
        client_->request_tiles(session_, missing, !index_received_);
        last_request_ms_ = now;
      }
    }
    if (!pending_event_.empty() && now - last_tiles_event_ms_ >= kTilesEventEveryMs) {
      nlohmann::json list = nlohmann::json::array();
      for (const auto& [id, version] : pending_event_) {
        const auto held = tiles_.held(id);
        std::size_t n = 0;
        if (held) n = held->points();
        list.push_back({{"id", std::to_string(id)}, {"v", version}, {"n", n}});
      }
      pending_event_.clear();
      last_tiles_event_ms_ = now;
      tiles_event = nlohmann::json{{"session", session_}, {"tiles", list}}.dump();
    }
    if (grid_changed_ && now - last_grid_event_ms_ >= kGridEventEveryMs) {
      grid_changed_ = false;
      last_grid_event_ms_ = now;
      grid_event = nlohmann::json{{"session", session_}, {"v", grid_.version_sum()}, {"patches", grid_.patch_count()}}.dump();
    }
  }
  if (link_lost)
    hub_.publish("link", nlohmann::json{{"up", false}, {"silent_ms", now - last_status_ms_}}.dump());
  if (!tiles_event.empty()) hub_.publish("tiles", std::move(tiles_event));
  if (!grid_event.empty()) hub_.publish("grid", std::move(grid_event));
}

nlohmann::json LiveFeed::snapshot() const {
  const std::lock_guard lock(mutex_);
  nlohmann::json path = nlohmann::json::array();
  for (const auto& p : path_) path.push_back({p.at[0], p.at[1], p.at[2], p.utime});
  nlohmann::json tiles = nlohmann::json::array();
  std::size_t points = 0;
  for (const auto& [id, changes] : changes_) {
    const auto held = tiles_.held(id);
    if (!held) continue;
    const std::size_t n = held->points();
    points += n;
    tiles.push_back({{"id", std::to_string(id)}, {"v", held->version}, {"n", n}});
  }
  return {{"payload", options_.payload_id},
          {"link", {{"up", link_up_}, {"silent_ms", link_up_ ? 0 : now_ms() - last_status_ms_}}},
          {"session", session_},
          {"status", status_ ? *status_ : nlohmann::json()},
          {"pose", pose_ ? *pose_ : nlohmann::json()},
          {"frame", frame_ ? *frame_ : nlohmann::json()},
          {"path", path},
          {"graph_path", graph_path_ ? *graph_path_ : nlohmann::json()},
          {"tiles", tiles},
          {"map_points", points},
          {"map_spill", spill_ ? nlohmann::json{{"bytes", spill_->live_bytes()},
                                                {"failed_writes", spill_->failed_writes()},
                                                {"failed_reads", spill_->failed_reads()}}
                               : nlohmann::json()},
          {"grid", grid_.patch_count() == 0
                       ? nlohmann::json()
                       : nlohmann::json{{"v", grid_.version_sum()}, {"patches", grid_.patch_count()}}}};
}

std::optional<TileBytes> LiveFeed::tile(std::int64_t id, std::int32_t held_version, int every) const {
  TileBytes out;
  std::vector<std::uint32_t> counts;          // every segment's points
  std::vector<protocol::HeldSegment> wanted;  // the segments from out.from on, copied (about 6 bytes a point)
  {
    const std::lock_guard lock(mutex_);
    const auto held = tiles_.held(id);
    if (!held) return std::nullopt;
    out.version = held->version;
    out.n_segments = static_cast<std::int32_t>(held->segments.size());
    // The first segment changed after the version the browser holds, when the
    // completions since are all known; otherwise the whole tile.
    if (held_version > 0 && held_version <= held->version) {
      const auto it = changes_.find(id);
      std::int32_t from = out.n_segments;
      std::int32_t reached = held->version;
      if (it != changes_.end())
        for (auto c = it->second.rbegin(); c != it->second.rend() && c->version > held_version; ++c) {
          from = std::min(from, c->from);
          reached = c->before;
        }
      out.from = reached <= held_version ? from : 0;
      if (held_version == held->version) out.from = out.n_segments;
    }
    for (std::size_t s = 0; s < held->segments.size(); ++s) {
      counts.push_back(held->segments[s].points);
      if (static_cast<std::int32_t>(s) >= out.from) wanted.push_back(held->segments[s]);
    }
  }
  // Decoded without the lock: the feed's thread goes on with poses meanwhile.
  const auto step = static_cast<std::size_t>(std::max(1, every));
  std::size_t index = 0;  // the point's place in the tile, for an even stride across segments
  std::vector<protocol::MapPoint> segment;
  for (std::size_t s = 0; s < counts.size(); ++s) {
    out.n_points += static_cast<std::int64_t>(counts[s]);
    if (static_cast<std::int32_t>(s) < out.from) {
      index += counts[s];
      continue;
    }
    segment.clear();
    wanted[s - static_cast<std::size_t>(out.from)].decode_into(segment);
    const std::size_t first = (step - index % step) % step;
    const std::size_t count = first < segment.size() ? (segment.size() - first + step - 1) / step : 0;
    append_u32(out.body, static_cast<std::uint32_t>(count));
    for (std::size_t i = first; i < segment.size(); i += step) {
      append_f32(out.body, static_cast<float>(segment[i].x));
      append_f32(out.body, static_cast<float>(segment[i].y));
      append_f32(out.body, static_cast<float>(segment[i].z));
    }
    index += counts[s];
  }
  return out;
}

std::shared_ptr<const GridBytes> LiveFeed::grid() const {
  protocol::GridImage image;
  std::string session;
  std::int64_t version = 0;
  std::size_t patches = 0;
  {
    const std::lock_guard lock(mutex_);
    if (grid_.patch_count() == 0) return nullptr;
    if (grid_png_ && grid_png_->session == session_ && grid_png_->version == grid_.version_sum()) return grid_png_;
    image = grid_.image();
    session = session_;
    version = grid_.version_sum();
    patches = grid_.patch_count();
  }
  // Encoded without the lock: the feed's thread goes on receiving meanwhile.
  auto encoded = std::make_shared<const GridBytes>(grid_bytes(image, std::move(session), version, patches));
  const std::lock_guard lock(mutex_);
  if (encoded->session == session_ && (!grid_png_ || grid_png_->version < encoded->version)) grid_png_ = encoded;
  return encoded;
}

std::optional<nlohmann::json> LiveFeed::grid_blocks() const {
  const std::lock_guard lock(mutex_);
  if (grid_.patch_count() == 0) return std::nullopt;
  const std::int32_t block_patches = grid_block_patches(grid_.patch_cells());
  const protocol::GridImage extent = grid_.extent();
  nlohmann::json blocks = nlohmann::json::array();
  for (const protocol::GridBlock& b : grid_.blocks(block_patches)) blocks.push_back({b.x, b.y, b.version});
  return nlohmann::json{{"session", session_},
                        {"v", grid_.version_sum()},
                        {"patches", grid_.patch_count()},
                        {"resolution", extent.resolution_m},
                        {"block_cells", block_patches * grid_.patch_cells()},
                        {"origin_x", extent.origin_x},
                        {"origin_y", extent.origin_y},
                        {"width", extent.width},
                        {"height", extent.height},
                        {"blocks", blocks}};
}

std::shared_ptr<const GridBytes> LiveFeed::grid_block(std::int32_t x, std::int32_t y) const {
  protocol::GridImage image;
  std::string session;
  protocol::GridBlock block;
  {
    const std::lock_guard lock(mutex_);
    if (grid_.patch_count() == 0) return nullptr;
    const std::int32_t block_patches = grid_block_patches(grid_.patch_cells());
    const std::optional<protocol::GridBlock> listed = grid_.block(block_patches, x, y);
    if (!listed) return nullptr;
    block = *listed;
    if (const auto held = block_pngs_.find({x, y}); held != block_pngs_.end() && held->second->version == block.version)
      return held->second;
    image = grid_.block_image(block_patches, x, y);
    session = session_;
  }
  // Encoded without the lock, as grid().
  auto encoded = std::make_shared<const GridBytes>(grid_bytes(image, std::move(session), block.version, block.patches));
  const std::lock_guard lock(mutex_);
  if (encoded->session == session_) {
    std::shared_ptr<const GridBytes>& held = block_pngs_[{x, y}];
    if (!held || held->version < encoded->version) held = encoded;
  }
  return encoded;
}

}  // namespace adit::tools::console
