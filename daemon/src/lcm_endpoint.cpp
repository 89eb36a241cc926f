#include "adit/daemon/lcm_endpoint.hpp"

#include <lcm/lcm-cpp.hpp>

#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/common/log.hpp"
#include "adit/command_ack_t.hpp"
#include "adit/daemon/graph_path.hpp"
#include "adit/daemon/handoff.hpp"
#include "adit/daemon/product_file_server.hpp"
#include "adit/daemon/tile_publisher.hpp"
#include "adit/pose_t.hpp"
#include "adit/protocol/channels.hpp"
#include "adit/protocol/checked_decode.hpp"
#include "adit/protocol/command_auth.hpp"
#include "adit/protocol/command_gate.hpp"
#include "adit/common/clock.hpp"
#include "adit/frame_t.hpp"
#include "adit/graph_path_t.hpp"
#include "adit/grid_patch_t.hpp"
#include "adit/loop_status_t.hpp"
#include "adit/status_t.hpp"
#include "adit/tile_segment_t.hpp"
#include "adit/tile_index_t.hpp"
#include "adit/tile_request_t.hpp"

namespace adit::daemon {
namespace {

using Clock = std::chrono::steady_clock;
using protocol::Channel;

// graph_path_t again this often after a change: for a client that lost it
// (UDP) or joined late; at most 48 KB each time.
constexpr double kGraphPathResendS = 5.0;

// The hand-offs carry items by swapping them with the pool's: the producer
// gets the slot's old buffers back, so nothing is allocated once warm.
template <typename T>
bool hand_over(Handoff<T>& handoff, T& item) {
  T* slot = handoff.acquire();
  if (slot == nullptr) return false;  // full: the caller counts the drop
  std::swap(*slot, item);
  handoff.publish(slot);
  return true;
}

template <typename T>
bool take_from(Handoff<T>& handoff, T& out) {
  T* slot = handoff.take();
  if (slot == nullptr) return false;
  std::swap(out, *slot);
  handoff.release(slot);
  return true;
}

// What tells a key file changed: a rewrite in place changes size or mtime, a
// rename over it (the safe way to rotate) changes the inode, chmod the ctime.
struct FileIdentity {
  bool exists = false;
  dev_t device = 0;
  ino_t inode = 0;
  off_t size = 0;
  std::int64_t mtime_ns = 0;
  std::int64_t ctime_ns = 0;  // chmod/chown
  bool operator==(const FileIdentity&) const = default;
};

FileIdentity identity_of(const std::filesystem::path& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return {};
  return {true, st.st_dev, st.st_ino, st.st_size,
          static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec,
          static_cast<std::int64_t>(st.st_ctim.tv_sec) * 1'000'000'000 + st.st_ctim.tv_nsec};
}

std::string key_ids(const std::vector<protocol::CommandKey>& keys) {
  std::string out;
  for (const protocol::CommandKey& k : keys) out += (out.empty() ? "" : ", ") + protocol::key_id_hex(k.id());
  return out;
}

TilePublisherOptions publisher_options(const EndpointOptions& o,
                                       std::function<std::string(const std::string&, TileStore&)> load) {
  return {o.payload_id, o.tiles, o.tile_period_s, o.chunk_bytes_per_s, o.drop_chunk_fraction, o.drop_seed,
          std::move(load)};
}

}  // namespace

struct LcmEndpoint::Impl final : TileSink, GridPatchSink {
  EndpointOptions options;
  SessionHooks hooks;
  lcm::LCM lcm;
  std::array<std::string, protocol::kChannelCount> channels;
  Handoff<PoseSample> poses;
  Handoff<StatusSample> statuses;
  Handoff<TileUpdate> tiles;
  std::atomic<std::uint64_t> tile_points_waiting{0};  // in `tiles`, not yet taken
  Handoff<GridPatchUpdate> grids;
  std::mutex events_mutex;  // control events are rare (button, end of flush)
  std::vector<protocol::SessionEvent> events;
  protocol::CommandGate gate;
  protocol::SessionMachine machine;
  std::atomic<protocol::SessionState> published_state{protocol::SessionState::idle};
  std::string session_id;
  TilePublisher publisher;
  GridPublisher grid_publisher;
  std::int64_t pose_seq = 0;
  MapFrame frame;  // the current (or last) session's, sent with each status
  // The current (or last) session's graph and its path, built once per
  // graph: sent when it changes and again every kGraphPathResendS.
  std::shared_ptr<const slam::CorrectionTrack> graph;
  graph_path_t graph_msg{};  // value-initialised: lcm-gen leaves numbers unset
  Clock::time_point graph_sent{};
  std::string stored_session;                // a stored session whose tiles the publisher holds
  std::optional<MapFrame> stored_frame;      // its frame (hooks.stored_frame)
  EndpointCounters counters;
  FileIdentity key_identity;
  Clock::time_point next_key_check{};
  std::uint64_t auth_rejections_logged = 0;
  Clock::time_point next_auth_log{};
  std::atomic<bool> running{true};
  std::thread thread;
  // Reused message buffers: no allocation per pose once warmed up.
  adit::pose_t pose_msg;
  std::vector<std::uint8_t> encode_buffer;

  Impl(EndpointOptions o, SessionHooks h)
      : options(std::move(o)),
        hooks(std::move(h)),
        lcm(options.lcm_url),
        poses(options.queue_capacity, Overflow::wait, [] { return PoseSample{}; }),
        statuses(options.queue_capacity, Overflow::wait, [] { return StatusSample{}; }),
        tiles(options.queue_capacity, Overflow::wait, [] { return TileUpdate{}; }),
        grids(options.queue_capacity, Overflow::wait, [] { return GridPatchUpdate{}; }),
        gate(options.payload_id, options.command_window),
        publisher(publisher_options(options,
                                    [this](const std::string& session, TileStore& into) {
                                      return load_stored(session, into);
                                    }),
                  *this),
        grid_publisher({options.payload_id, options.grid_period_s, options.grid_refresh_s}, *this) {
    if (const std::string problem = protocol::payload_id_problem(options.payload_id); !problem.empty())
      throw InputError("payload id", "payload_id", problem);
    if (const std::string problem = protocol::tile_params_problem(options.tiles); !problem.empty())
      throw InputError("tile parameters", "tiles", problem);
    if (!lcm.good()) throw std::runtime_error(fmt::format("LCM cannot open '{}'", options.lcm_url));
    load_keys();
    for (int c = 0; c < protocol::kChannelCount; ++c) channels[c] = protocol::channel_name(options.payload_id, static_cast<Channel>(c));
    lcm.subscribe(channel(Channel::command), &Impl::on_command, this);
    lcm.subscribe(channel(Channel::tile_request), &Impl::on_tile_request, this);
    lcm.subscribe(channel(Channel::file_request), &Impl::on_file_request, this);
    thread = std::thread([this] { run(); });
  }

  ~Impl() override {
    running = false;
    if (thread.joinable()) thread.join();
  }

  const std::string& channel(Channel c) const { return channels[static_cast<std::size_t>(c)]; }

  template <typename Message>
  void send(Channel c, const Message& message) {
    const int size = message.getEncodedSize();
    encode_buffer.resize(static_cast<std::size_t>(size));
    message.encode(encode_buffer.data(), 0, size);
    std::uint64_t largest = counters.largest_message_bytes.load();
    while (static_cast<std::uint64_t>(size) > largest &&
           !counters.largest_message_bytes.compare_exchange_weak(largest, static_cast<std::uint64_t>(size))) {
    }
    lcm.publish(channel(c), encode_buffer.data(), static_cast<unsigned>(size));
  }

  void send(const tile_segment_t& segment) override { send(Channel::tile, segment); }
  void send(const tile_index_t& index) override { send(Channel::tile_index, index); }
  void send(const grid_patch_t& patch) override { send(Channel::grid, patch); }

  // --- keys ---------------------------------------------------------------

  // At start: a configured key file that cannot be used is an error (aditd
  // exits 2), never a silent fall-back to unauthenticated commands.
  void load_keys() {
    if (options.key_file.empty()) {
      log::warn("commands are not authenticated: no lcm.key_file is configured, so anyone on the network can "
                "START/STOP this payload (docs/PROTOCOL.md, threat model)");
      return;
    }
    key_identity = identity_of(options.key_file);
    std::vector<protocol::CommandKey> keys = protocol::read_key_file(options.key_file);
    log::info("commands: signed commands only, {} key(s) from {} (key id {}), window ±{:.0f} s", keys.size(),
              options.key_file.string(), key_ids(keys), options.command_window_s);
    gate.set_keys(std::move(keys), static_cast<std::int64_t>(options.command_window_s * 1e6));
    counters.commands_authenticated = true;
  }

  // Key rotation without a restart: re-read the file when it changed. A file
  // that vanished or went bad keeps the keys in force (logged once per change).
  void check_key_file() {
    if (options.key_file.empty() || Clock::now() < next_key_check) return;
    next_key_check = Clock::now() + std::chrono::microseconds(static_cast<std::int64_t>(options.key_check_period_s * 1e6));
    const FileIdentity now = identity_of(options.key_file);
    if (now == key_identity) return;
    key_identity = now;
    try {
      std::vector<protocol::CommandKey> keys = protocol::read_key_file(options.key_file);
      log::info("commands: key file {} changed: now {} key(s) (key id {})", options.key_file.string(), keys.size(),
                key_ids(keys));
      gate.set_keys(std::move(keys), gate.window_us());
      ++counters.key_reloads;
    } catch (const std::exception& e) {
      ++counters.key_reload_errors;
      log::error("commands: the changed key file is refused, the previous keys stay in force: {}", e.what());
    }
  }

  void log_auth_rejections() {
    const protocol::GateCounts& n = gate.counts();
    const std::uint64_t total = n.unsigned_commands + n.bad_tag + n.stale + n.replay_rejected + n.other_payload;
    if (total == auth_rejections_logged || Clock::now() < next_auth_log) return;
    auth_rejections_logged = total;
    next_auth_log = Clock::now() + std::chrono::seconds(5);  // a flood is summed, not logged per message
    log::warn("commands rejected so far: {} unsigned, {} bad tag, {} stale, {} replayed, {} for another payload",
              n.unsigned_commands, n.bad_tag, n.stale, n.replay_rejected, n.other_payload);
  }

  void run() {
    while (running) {
      lcm.handleTimeout(2);
      check_key_file();
      log_auth_rejections();
      drain_events();
      drain_poses();
      drain_status();
      TileUpdate t;
      while (take_from(tiles, t)) {
        publisher.update(t.key, t.first_point, t.points, t.utime);
        tile_points_waiting.fetch_sub(t.points.size(), std::memory_order_relaxed);
        // take_from gives the slot what `t` held: it must be nothing, or each
        // of the queue's slots would keep a whole tile's points (up to ~19 MB)
        // until the producer comes round to it again.
        std::vector<protocol::MapPoint>().swap(t.points);
      }
      publisher.tick(Clock::now());
      GridPatchUpdate g;
      while (take_from(grids, g)) grid_publisher.update(g);
      grid_publisher.tick(Clock::now());
      counters.grid_patches_published = grid_publisher.counts().patches_sent;
      counters.grid_bytes_published = grid_publisher.counts().bytes_sent;
      const TilePublisherCounts& c = publisher.counts();
      counters.chunks_published = c.chunks_published;
      counters.chunks_dropped_by_hook = c.chunks_dropped_by_hook;
      counters.chunk_bytes_published = c.chunk_bytes_published;
      counters.index_published = c.index_published;
      counters.segment_read_errors = c.segment_read_errors;
    }
  }

  // --- commands -----------------------------------------------------------

  void on_command(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
    protocol::GateResult r = gate.inspect(rbuf->data, rbuf->data_size, realtime_us());
    const protocol::GateCounts& n = gate.counts();
    counters.commands_unsigned = n.unsigned_commands;
    counters.commands_bad_tag = n.bad_tag;
    counters.commands_stale = n.stale;
    counters.commands_replay_rejected = n.replay_rejected;
    counters.commands_other_payload = n.other_payload;
    using Kind = protocol::GateResult::Kind;
    if (r.kind == Kind::malformed) {
      ++counters.commands_malformed;
      return;
    }
    if (r.kind == Kind::replay) {
      ++counters.commands_replayed;
      send(Channel::ack, r.previous);
      return;
    }
    command_ack_t ack;
    ack.utime = realtime_us();
    ack.schema = 1;
    ack.request_id = r.command.request_id;
    ack.payload_id = options.payload_id;
    if (r.kind == Kind::reject) {
      ack.accepted = false;
      ack.reason = r.reason;
    } else {
      // A hook that throws must not take the endpoint thread down: the
      // command is answered as failed and the state stays as it was.
      try {
        execute(r.verb, r.command, ack);
      } catch (const std::exception& e) {
        ack.accepted = false;
        ack.reason = fmt::format("{} failed: {}", protocol::verb_name(r.verb), e.what());
      }
    }
    (ack.accepted ? counters.commands_executed : counters.commands_rejected)++;
    ack.state = static_cast<std::int8_t>(machine.state());
    ack.session_id = session_id;
    if (r.remember) gate.remember(ack);
    send(Channel::ack, ack);
  }

  void execute(protocol::Verb verb, const command_t& command, command_ack_t& ack) {
    using protocol::Verb;
    switch (verb) {
      case Verb::start: {
        apply_transition(protocol::SessionEvent::start, ack);
        return;
      }
      case Verb::stop: {
        apply_transition(protocol::SessionEvent::stop, ack);
        return;
      }
      case Verb::ping:
        ack.accepted = true;
        ack.reason = "pong";
        return;
      case Verb::sessions: {
        ack.accepted = true;
        ack.reason = "sessions listed";
        if (hooks.sessions)
          for (const std::string& s : hooks.sessions()) ack.detail += s + "\n";
        return;
      }
      case Verb::hint: {
        std::string problem;
        const std::optional<protocol::LocaliseHint> hint = protocol::parse_localise_hint(command.args, problem);
        if (hint && machine.state() != protocol::SessionState::mapping) problem = "no session is mapping";
        if (hint && problem.empty()) problem = hooks.hint ? hooks.hint(*hint) : "this daemon has no prior map";
        ack.accepted = problem.empty();
        ack.reason = ack.accepted ? "hint taken" : problem;  // the client says "HINT rejected: …"
        return;
      }
      case Verb::export_map: {
        if (!hooks.export_map) {
          ack.accepted = false;
          ack.reason = "this daemon cannot export";
          return;
        }
        const std::string session = command.args.empty() ? session_id : command.args.front();
        ack.accepted = true;
        ack.reason = "exported";
        ack.detail = hooks.export_map(session, command.args);
        return;
      }
    }
  }

  // The hooks run before the machine moves, so a hook that throws leaves the
  // state unchanged.
  void apply_transition(protocol::SessionEvent event, command_ack_t& ack) {
    const protocol::Transition t = protocol::next_state(machine.state(), event);
    ack.accepted = t.accepted;
    ack.reason = t.reason;
    if (!t.accepted) return;
    if (event == protocol::SessionEvent::start) {
      std::string started = hooks.start ? hooks.start() : fmt::format("session-{}", realtime_us());
      session_id = std::move(started);
      publisher.reset(session_id, hooks.session_folder ? hooks.session_folder(session_id) : std::filesystem::path{});
      grid_publisher.reset(session_id);
      pose_seq = 0;
      frame = MapFrame{};
      graph.reset();
      graph_msg.revision = 0;
      ack.reason += ": session " + session_id;
    } else if (event == protocol::SessionEvent::stop && hooks.stop) {
      hooks.stop();
    }
    machine.apply(event);
    published_state = machine.state();
  }

  void drain_events() {
    std::vector<protocol::SessionEvent> pending;
    {
      const std::lock_guard lock(events_mutex);
      pending.swap(events);
    }
    for (const protocol::SessionEvent event : pending) {
      command_ack_t result;
      try {
        apply_transition(event, result);
      } catch (const std::exception& e) {
        result.accepted = false;
        result.reason = e.what();
      }
      if (!result.accepted) log::warn("session: {} ({})", result.reason, protocol::state_name(machine.state()));
    }
  }

  // --- poses, status --------------------------------------------------------

  void drain_poses() {
    PoseSample p;
    while (take_from(poses, p)) {
      pose_msg.utime = p.utime;
      pose_msg.schema = 1;
      pose_msg.session_id = session_id;
      pose_msg.seq = pose_seq++;
      std::copy(p.position.begin(), p.position.end(), pose_msg.position);
      std::copy(p.orientation.begin(), p.orientation.end(), pose_msg.orientation);
      std::copy(p.covariance.begin(), p.covariance.end(), pose_msg.covariance);
      pose_msg.flags = p.flags;
      send(Channel::pose, pose_msg);
      ++counters.poses_published;
    }
  }

  void drain_status() {
    StatusSample s;
    while (take_from(statuses, s)) {
      // Before the status it goes with: a client that shows both at each
      // status has this period's loops.
      if (s.loops && !session_id.empty()) send_loop_status(s.utime, *s.loops);
      status_t m;
      m.utime = s.utime;
      m.schema = 1;
      m.payload_id = options.payload_id;
      m.state = static_cast<std::int8_t>(machine.state());
      m.session_id = session_id;
      for (const SensorHealth& h : s.sensors)
        m.sensors.push_back({h.name, h.packet_rate_hz, h.packets_dropped, h.last_seen_utime, h.time_offset_s});
      m.n_sensors = static_cast<std::int32_t>(m.sensors.size());
      for (const ThreadLoad& t : s.threads) m.threads.push_back({t.name, t.load, t.queue_depth, t.queue_capacity});
      m.n_threads = static_cast<std::int32_t>(m.threads.size());
      m.disk_free_bytes = s.disk_free_bytes;
      m.map_points = publisher.store().total_points();
      m.map_tiles = static_cast<std::int32_t>(publisher.store().tiles().size());
      m.fault = s.fault;
      send(Channel::status, m);
      ++counters.status_published;
      if (s.frame) frame = *s.frame;
      if (!session_id.empty()) send_frame(m.utime, session_id, frame);
      const bool changed = s.graph != nullptr && s.graph != graph;
      if (changed) {
        graph = std::move(s.graph);
        build_graph_path();
      }
      if (graph != nullptr && !session_id.empty() &&
          (changed || Clock::now() - graph_sent >= std::chrono::duration<double>(kGraphPathResendS))) {
        send(Channel::graph_path, graph_msg);
        graph_sent = Clock::now();
        ++counters.graph_paths_published;
      }
    }
  }

  void send_loop_status(std::int64_t utime, const LoopStatus& loops) {
    loop_status_t m;
    m.utime = utime;
    m.schema = 1;
    m.payload_id = options.payload_id;
    m.session_id = session_id;
    m.keyframes = loops.keyframes;
    m.candidates = loops.candidates;
    m.accepted = loops.accepted;
    m.rejected = loops.rejected;
    m.last_loop_utime = loops.last_loop_utime;
    m.correction_m = loops.correction_m;
    m.correction_deg = loops.correction_deg;
    m.moves_map = loops.moves_map ? 1 : 0;
    send(Channel::loops, m);
    ++counters.loop_statuses_published;
  }

  // The new graph's keyframes for a client that draws the path with the map
  // the loops moved (graph_path.hpp, docs/PROTOCOL.md), its next revision.
  void build_graph_path() {
    const GraphPath path = graph_path_of(*graph);
    graph_msg.utime = path.utime;
    graph_msg.schema = 1;
    graph_msg.payload_id = options.payload_id;
    graph_msg.session_id = session_id;
    ++graph_msg.revision;
    graph_msg.n_keyframes = path.n_keyframes;
    graph_msg.n = static_cast<std::int32_t>(path.positions.size());
    graph_msg.positions.clear();
    graph_msg.positions.reserve(path.positions.size());
    for (const auto& p : path.positions) graph_msg.positions.push_back({p[0], p[1], p[2]});
  }

  // The session's frame, for a client that draws its poses and tiles in the
  // map frame (the prior's once anchored; docs/PROTOCOL.md).
  void send_frame(std::int64_t utime, const std::string& session, const MapFrame& placing) {
    frame_t f;
    f.utime = utime;
    f.schema = 2;
    f.payload_id = options.payload_id;
    f.session_id = session;
    f.source = placing.source;
    std::copy(placing.position.begin(), placing.position.end(), f.position);
    std::copy(placing.orientation.begin(), placing.orientation.end(), f.orientation);
    std::copy(placing.tiles_position.begin(), placing.tiles_position.end(), f.tiles_position);
    std::copy(placing.tiles_orientation.begin(), placing.tiles_orientation.end(), f.tiles_orientation);
    send(Channel::frame, f);
    ++counters.frames_published;
  }

  // --- tiles ----------------------------------------------------------------

  std::string load_stored(const std::string& session, TileStore& into) {
    if (machine.state() != protocol::SessionState::idle)
      return fmt::format("mapping session '{}' is running: download other sessions after STOP", session_id);
    if (!hooks.load_tiles) return fmt::format("session '{}' is not held by this daemon", session);
    std::string problem = hooks.load_tiles(session, into);
    if (problem.empty()) {
      stored_session = session;
      stored_frame = hooks.stored_frame ? hooks.stored_frame(session) : std::nullopt;
    }
    return problem;
  }

  void on_tile_request(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
    tile_request_t r;
    if (!protocol::checked_decode(rbuf->data, rbuf->data_size, r) || r.payload_id != options.payload_id) {
      ++counters.tile_requests_malformed;
      return;
    }
    ++counters.tile_requests;
    publisher.answer(r);
    // A stored session's frame goes with each answer for its tiles (a live
    // session's goes with the status): a client downloading it after a
    // restart places them in its map frame.
    if (stored_frame && !stored_session.empty() && publisher.session_id() == stored_session)
      send_frame(realtime_us(), stored_session, *stored_frame);
  }

  // A stored session's product file (product_file_server.hpp); "" names the last session.
  void on_file_request(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
    file_request_t r;
    if (!protocol::checked_decode(rbuf->data, rbuf->data_size, r) || r.payload_id != options.payload_id) {
      ++counters.file_requests_malformed;
      return;
    }
    ++counters.file_requests;
    counters.file_chunks_published += answer_file_request(r, r.session_id.empty() ? session_id : r.session_id,
                                                          hooks.session_folder,
                                                          [this](const file_chunk_t& c) { send(Channel::file, c); });
  }
};

LcmEndpoint::LcmEndpoint(EndpointOptions options, SessionHooks hooks)
    : impl_(std::make_unique<Impl>(std::move(options), std::move(hooks))) {}

LcmEndpoint::~LcmEndpoint() = default;

bool LcmEndpoint::publish_pose(const PoseSample& pose) {
  PoseSample copy = pose;
  if (hand_over(impl_->poses, copy)) return true;
  ++impl_->counters.poses_dropped;
  return false;
}

bool LcmEndpoint::publish_status(StatusSample&& status) {
  if (hand_over(impl_->statuses, status)) return true;
  ++impl_->counters.status_dropped;
  return false;
}

bool LcmEndpoint::publish_grid(GridPatchUpdate&& patch) {
  if (hand_over(impl_->grids, patch)) return true;
  ++impl_->counters.grid_patches_dropped;
  return false;
}

bool LcmEndpoint::publish_tile(TileUpdate&& tile) {
  const std::size_t points = tile.points.size();
  impl_->tile_points_waiting.fetch_add(points, std::memory_order_relaxed);
  if (hand_over(impl_->tiles, tile)) return true;
  impl_->tile_points_waiting.fetch_sub(points, std::memory_order_relaxed);
  ++impl_->counters.tiles_dropped;
  return false;
}

void LcmEndpoint::session_stopped() {
  const std::lock_guard lock(impl_->events_mutex);
  impl_->events.push_back(protocol::SessionEvent::stopped);
}

void LcmEndpoint::button_pressed() {
  const std::lock_guard lock(impl_->events_mutex);
  impl_->events.push_back(impl_->published_state.load() == protocol::SessionState::idle ? protocol::SessionEvent::start
                                                                                        : protocol::SessionEvent::stop);
}

void LcmEndpoint::start_session() {
  const std::lock_guard lock(impl_->events_mutex);
  impl_->events.push_back(protocol::SessionEvent::start);
}

void LcmEndpoint::stop_session() {
  const std::lock_guard lock(impl_->events_mutex);
  impl_->events.push_back(protocol::SessionEvent::stop);
}

protocol::SessionState LcmEndpoint::state() const { return impl_->published_state.load(); }

std::uint64_t LcmEndpoint::tile_points_waiting() const {
  return impl_->tile_points_waiting.load(std::memory_order_relaxed);
}

const EndpointCounters& LcmEndpoint::counters() const { return impl_->counters; }

}  // namespace adit::daemon
