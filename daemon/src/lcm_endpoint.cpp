#include "adit/daemon/lcm_endpoint.hpp"

#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <chrono>
#include <deque>
#include <mutex>
#include <random>
#include <set>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/common/log.hpp"
#include "adit/command_ack_t.hpp"
#include "adit/daemon/spsc_queue.hpp"
#include "adit/daemon/tile_store.hpp"
#include "adit/pose_t.hpp"
#include "adit/protocol/channels.hpp"
#include "adit/protocol/checked_decode.hpp"
#include "adit/protocol/command_gate.hpp"
#include "adit/status_t.hpp"
#include "adit/tile_chunk_t.hpp"
#include "adit/tile_index_t.hpp"
#include "adit/tile_request_t.hpp"

namespace adit::daemon {
namespace {

using Clock = std::chrono::steady_clock;
using protocol::Channel;

std::int64_t now_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Index entries per tile_index_t: 20 bytes each, 2000 keep a part near 40 KB.
constexpr std::size_t kIndexEntriesPerPart = 2000;

struct ChunkRef {
  std::int64_t tile_id;
  std::int32_t version;
  std::int32_t chunk;
  auto operator<=>(const ChunkRef&) const = default;
};

}  // namespace

struct LcmEndpoint::Impl {
  EndpointOptions options;
  SessionHooks hooks;
  lcm::LCM lcm;
  std::array<std::string, 7> channels;
  SpscQueue<PoseSample> poses;
  SpscQueue<StatusSample> statuses;
  SpscQueue<TileUpdate> tiles;
  std::mutex events_mutex;  // control events are rare (button, end of flush)
  std::vector<protocol::SessionEvent> events;
  protocol::CommandGate gate;
  protocol::SessionMachine machine;
  std::atomic<protocol::SessionState> published_state{protocol::SessionState::idle};
  std::string session_id;
  TileStore store;
  std::set<std::int64_t> dirty;
  std::deque<ChunkRef> outgoing;
  std::set<ChunkRef> queued;
  double send_budget_bytes = 0;
  Clock::time_point last_budget = Clock::now();
  Clock::time_point last_tile_broadcast = Clock::now();
  std::int64_t pose_seq = 0;
  std::mt19937 drop_rng;
  std::uniform_real_distribution<double> unit{0.0, 1.0};
  EndpointCounters counters;
  std::atomic<bool> running{true};
  std::thread thread;
  // Reused message buffers: no allocation per pose once warmed up.
  adit::pose_t pose_msg;
  std::vector<std::uint8_t> encode_buffer;

  Impl(EndpointOptions o, SessionHooks h)
      : options(std::move(o)),
        hooks(std::move(h)),
        lcm(options.lcm_url),
        poses(options.queue_capacity),
        statuses(options.queue_capacity),
        tiles(options.queue_capacity),
        gate(options.payload_id, options.command_window),
        store(options.tiles),
        drop_rng(options.drop_seed) {
    if (const std::string problem = protocol::payload_id_problem(options.payload_id); !problem.empty())
      throw InputError("payload id", "payload_id", problem);
    if (const std::string problem = protocol::tile_params_problem(options.tiles); !problem.empty())
      throw InputError("tile parameters", "tiles", problem);
    if (!lcm.good()) throw std::runtime_error(fmt::format("LCM cannot open '{}'", options.lcm_url));
    for (int c = 0; c < 7; ++c) channels[c] = protocol::channel_name(options.payload_id, static_cast<Channel>(c));
    lcm.subscribe(channel(Channel::command), &Impl::on_command, this);
    lcm.subscribe(channel(Channel::tile_request), &Impl::on_tile_request, this);
    thread = std::thread([this] { run(); });
  }

  ~Impl() {
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

  void run() {
    while (running) {
      lcm.handleTimeout(2);
      drain_events();
      drain_poses();
      drain_status();
      drain_tiles();
      broadcast_changed_tiles();
      send_chunks();
    }
  }

  // --- commands -----------------------------------------------------------

  void on_command(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
    protocol::GateResult r = gate.inspect(rbuf->data, rbuf->data_size);
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
    ack.utime = now_utime();
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
    gate.remember(ack);
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
      std::string started = hooks.start ? hooks.start() : fmt::format("session-{}", now_utime());
      session_id = std::move(started);
      store = TileStore(options.tiles);
      dirty.clear();
      outgoing.clear();
      queued.clear();
      pose_seq = 0;
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
    while (poses.pop(p)) {
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
    while (statuses.pop(s)) {
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
      m.map_points = store.total_points();
      m.map_tiles = static_cast<std::int32_t>(store.tiles().size());
      m.fault = s.fault;
      send(Channel::status, m);
      ++counters.status_published;
    }
  }

  // --- tiles ----------------------------------------------------------------

  void drain_tiles() {
    TileUpdate t;
    while (tiles.pop(t)) dirty.insert(store.update(t.key, t.points, t.utime).id);
  }

  void broadcast_changed_tiles() {
    const auto now = Clock::now();
    if (dirty.empty() || now - last_tile_broadcast < std::chrono::duration<double>(options.tile_period_s)) return;
    last_tile_broadcast = now;
    // The index of just the changed tiles: a full one costs 20 bytes per tile
    // every second; clients ask for it once (want_index).
    std::vector<const EncodedTile*> changed;
    for (const std::int64_t id : dirty) {
      changed.push_back(store.find(id));
      queue_tile(*changed.back(), -1);
    }
    dirty.clear();
    send_index_parts(changed, false, "");
  }

  void queue_tile(const EncodedTile& tile, std::int32_t only_chunk) {
    for (std::int32_t c = 0; c < tile.n_chunks; ++c) {
      if (only_chunk >= 0 && c != only_chunk) continue;
      const ChunkRef ref{tile.id, tile.version, c};
      if (queued.insert(ref).second) outgoing.push_back(ref);
    }
  }

  void send_index() {
    std::vector<const EncodedTile*> all;
    for (const auto& [id, tile] : store.tiles()) all.push_back(&tile);
    send_index_parts(all, true, "");
  }

  void send_index_parts(const std::vector<const EncodedTile*>& all, bool full, const std::string& error) {
    const std::int32_t n_parts =
        static_cast<std::int32_t>(std::max<std::size_t>(1, (all.size() + kIndexEntriesPerPart - 1) / kIndexEntriesPerPart));
    std::array<float, 3> lo{0, 0, 0};
    std::array<float, 3> hi{0, 0, 0};
    bool first = true;
    for (const auto& [id, tile] : store.tiles()) {  // bounds of the whole map
      const protocol::TileKey k = protocol::tile_key(id);
      const std::array<double, 3> a{k.x * options.tiles.tile_size_m, k.y * options.tiles.tile_size_m,
                                    k.z * options.tiles.tile_size_m};
      for (int i = 0; i < 3; ++i) {
        lo[i] = first ? static_cast<float>(a[i]) : std::min(lo[i], static_cast<float>(a[i]));
        hi[i] = first ? static_cast<float>(a[i] + options.tiles.tile_size_m)
                      : std::max(hi[i], static_cast<float>(a[i] + options.tiles.tile_size_m));
      }
      first = false;
    }
    for (std::int32_t part = 0; part < n_parts; ++part) {
      tile_index_t m;
      m.utime = now_utime();
      m.schema = 1;
      m.payload_id = options.payload_id;
      m.session_id = session_id;
      m.error = error;
      m.tile_size_m = static_cast<float>(options.tiles.tile_size_m);
      m.full = full;
      m.part = part;
      m.n_parts = n_parts;
      const std::size_t begin = static_cast<std::size_t>(part) * kIndexEntriesPerPart;
      const std::size_t end = std::min(all.size(), begin + kIndexEntriesPerPart);
      for (std::size_t i = begin; i < end; ++i) {
        m.tile_ids.push_back(all[i]->id);
        m.versions.push_back(all[i]->version);
        m.n_chunks.push_back(all[i]->n_chunks);
        m.n_points.push_back(all[i]->n_points);
      }
      m.n_tiles = static_cast<std::int32_t>(m.tile_ids.size());
      m.total_points = store.total_points();
      std::copy(lo.begin(), lo.end(), m.bounds_min);
      std::copy(hi.begin(), hi.end(), m.bounds_max);
      send(Channel::tile_index, m);
      ++counters.index_published;
    }
  }

  void on_tile_request(const lcm::ReceiveBuffer* rbuf, const std::string& /*channel*/) {
    tile_request_t r;
    if (!protocol::checked_decode(rbuf->data, rbuf->data_size, r) || r.payload_id != options.payload_id) {
      ++counters.tile_requests_malformed;
      return;
    }
    ++counters.tile_requests;
    if (!r.session_id.empty() && r.session_id != session_id) {
      // Only the current (or last) session's tiles are held in memory.
      send_index_parts({}, true, fmt::format("session '{}' is not held by this daemon (it holds '{}')", r.session_id,
                                       session_id));
      return;
    }
    if (r.want_index) send_index();
    for (std::size_t i = 0; i < r.tile_ids.size(); ++i) {
      const EncodedTile* tile = store.find(r.tile_ids[i]);
      if (tile == nullptr) continue;
      // A client asking for an older version gets the current one whole.
      const bool same = tile->version == r.versions[i];
      queue_tile(*tile, same ? r.chunks[i] : -1);
    }
  }

  // Sends queued chunks at options.chunk_bytes_per_s: a burst of a whole map
  // would overflow the receivers' socket buffers and the Wi-Fi link.
  void send_chunks() {
    const auto now = Clock::now();
    const double elapsed = std::chrono::duration<double>(now - last_budget).count();
    last_budget = now;
    // At most two chunks back to back: a receiver's default socket buffer
    // (212 992 bytes on Linux) holds little more.
    send_budget_bytes = std::min(send_budget_bytes + elapsed * options.chunk_bytes_per_s,
                                 2.0 * protocol::kChunkPayloadBytes);
    while (!outgoing.empty() && send_budget_bytes > 0) {
      const ChunkRef ref = outgoing.front();
      outgoing.pop_front();
      queued.erase(ref);
      const EncodedTile* tile = store.find(ref.tile_id);
      if (tile == nullptr || tile->version != ref.version) continue;  // superseded: the new version is queued
      const auto piece = protocol::chunk_of(tile->blob, ref.chunk);
      send_budget_bytes -= static_cast<double>(piece.size());
      if (options.drop_chunk_fraction > 0 && unit(drop_rng) < options.drop_chunk_fraction) {
        ++counters.chunks_dropped_by_hook;
        continue;
      }
      tile_chunk_t m;
      m.utime = tile->utime;
      m.schema = 1;
      m.payload_id = options.payload_id;
      m.session_id = session_id;
      m.tile_id = tile->id;
      m.version = tile->version;
      m.chunk = ref.chunk;
      m.n_chunks = tile->n_chunks;
      m.data.assign(piece.begin(), piece.end());
      m.size = static_cast<std::int32_t>(m.data.size());
      send(Channel::tile, m);
      ++counters.chunks_published;
      counters.chunk_bytes_published += static_cast<std::uint64_t>(m.getEncodedSize());
    }
  }
};

LcmEndpoint::LcmEndpoint(EndpointOptions options, SessionHooks hooks)
    : impl_(std::make_unique<Impl>(std::move(options), std::move(hooks))) {}

LcmEndpoint::~LcmEndpoint() = default;

bool LcmEndpoint::publish_pose(const PoseSample& pose) {
  if (impl_->poses.push(pose)) return true;
  ++impl_->counters.poses_dropped;
  return false;
}

bool LcmEndpoint::publish_status(StatusSample&& status) {
  if (impl_->statuses.push(std::move(status))) return true;
  ++impl_->counters.status_dropped;
  return false;
}

bool LcmEndpoint::publish_tile(TileUpdate&& tile) {
  if (impl_->tiles.push(std::move(tile))) return true;
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

protocol::SessionState LcmEndpoint::state() const { return impl_->published_state.load(); }

const EndpointCounters& LcmEndpoint::counters() const { return impl_->counters; }

}  // namespace adit::daemon
