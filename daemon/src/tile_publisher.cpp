#include "adit/daemon/tile_publisher.hpp"
#include "adit/common/clock.hpp"

#include <algorithm>
#include <array>

#include <fmt/format.h>

#include "adit/common/log.hpp"

namespace adit::daemon {
namespace {

// Index entries per tile_index_t: 20 bytes each, 2000 keep a part near 40 KB.
constexpr std::size_t kIndexEntriesPerPart = 2000;
// At most two chunks back to back: a receiver's default socket buffer
// (212 992 bytes on Linux) holds little more.
constexpr double kBurstBytes = 2.0 * protocol::kChunkPayloadBytes;


}  // namespace

TilePublisher::TilePublisher(TilePublisherOptions options, TileSink& sink)
    : options_(std::move(options)),
      sink_(sink),
      store_(options_.tiles),
      budget_bytes_(kBurstBytes),
      drop_rng_(options_.drop_seed) {}

void TilePublisher::reset(std::string session_id, const std::filesystem::path& spool_dir) {
  session_id_ = std::move(session_id);
  store_ = TileStore(options_.tiles);  // the last session's spool goes first
  if (!spool_dir.empty()) {
    store_ = TileStore(options_.tiles, spool_dir);
    if (!store_.spool_problem().empty())
      log::error("tile stream: {} (segments stay in RAM this session)", store_.spool_problem());
  }
  reported_write_errors_ = 0;
  session_read_errors_ = 0;
  dirty_.clear();
  broadcast_version_.clear();
  outgoing_.clear();
  queued_.clear();
}

void TilePublisher::update(protocol::TileKey key, std::size_t first_point,
                           std::span<const protocol::MapPoint> points, std::int64_t utime) {
  bool changed = false;
  if (first_point == 0) {
    changed = store_.update(key, points, utime);
  } else if (const std::string problem = store_.append(key, first_point, points, utime, changed); !problem.empty()) {
    if (counts_.updates_refused++ == 0) log::error("tile stream: {}", problem);
  }
  if (changed) dirty_.insert(protocol::tile_id(key));
  if (store_.spool_write_errors() > 0 && reported_write_errors_ == 0)
    log::error("tile stream: {} (such segments stay in RAM)", store_.first_write_problem());
  reported_write_errors_ = store_.spool_write_errors();
}

void TilePublisher::answer(const tile_request_t& request) {
  if (!request.session_id.empty() && request.session_id != session_id_) {
    // The current (or last) session's tiles are in memory; others come from disk.
    std::string problem = fmt::format("session '{}' is not held by this daemon (it holds '{}')", request.session_id,
                                      session_id_);
    if (options_.load_session) {
      TileStore loaded(options_.tiles);
      problem = options_.load_session(request.session_id, loaded);
      if (problem.empty()) {
        reset(request.session_id);
        store_ = std::move(loaded);
      }
    }
    if (!problem.empty()) {
      send_index({}, true, request.request_id, problem);
      return;
    }
  }
  if (request.want_index) {
    std::vector<const EncodedTile*> all;
    for (const auto& [id, tile] : store_.tiles()) all.push_back(&tile);
    send_index(all, true, request.request_id, "");
  }
  const std::size_t n = std::min({request.tile_ids.size(), request.versions.size(), request.chunks.size()});
  for (std::size_t i = 0; i < n; ++i) {
    const EncodedTile* tile = store_.find(request.tile_ids[i]);
    if (tile == nullptr) continue;
    // A version this daemon never had (another run's) counts as nothing held;
    // so does any version in a schema-1 request (it named the version wanted).
    const std::int32_t asked = request.schema >= 2 ? request.versions[i] : 0;
    const std::int32_t held = asked > tile->version ? 0 : std::max(0, asked);
    if (held == tile->version) continue;  // it has this version already
    queue_segments(*tile, held, request.chunks[i]);
  }
}

void TilePublisher::tick(Clock::time_point now) {
  if (!dirty_.empty() && now - last_broadcast_ >= std::chrono::duration<double>(options_.period_s)) {
    last_broadcast_ = now;
    // Listeners that followed the stream hold each tile at its last
    // broadcast version: the segments changed since then bring them up to
    // date. Then the index of just the changed tiles: a full one costs 20
    // bytes per tile every second; clients ask for that once (want_index).
    std::vector<const EncodedTile*> changed;
    for (const std::int64_t id : dirty_) {
      changed.push_back(store_.find(id));
      std::int32_t& base = broadcast_version_[id];
      queue_segments(*changed.back(), base, -1);
      base = changed.back()->version;
    }
    dirty_.clear();
    send_index(changed, false, 0, "");
  }
  send_chunks(now);
}

void TilePublisher::queue_segments(const EncodedTile& tile, std::int32_t base, std::int32_t only_segment) {
  if (only_segment >= tile.n_segments()) return;  // no such segment (a request from the network)
  const auto first = static_cast<std::int32_t>(protocol::first_segment_after(tile.segments, base));
  const std::int32_t begin = only_segment >= 0 ? only_segment : first;
  const std::int32_t end = only_segment >= 0 ? only_segment + 1 : tile.n_segments();
  for (std::int32_t s = begin; s < end; ++s) {
    const SegmentRef ref{tile.id, s};
    const auto [it, added] = queued_.emplace(ref, base);
    if (added) outgoing_.push_back(ref);
    else it->second = std::min(it->second, base);
  }
}

void TilePublisher::send_index(const std::vector<const EncodedTile*>& tiles, bool full, std::int64_t request_id,
                               const std::string& error) {
  const double size = options_.tiles.tile_size_m;
  std::array<float, 3> lo{0, 0, 0};
  std::array<float, 3> hi{0, 0, 0};
  bool first = true;
  for (const auto& [id, tile] : store_.tiles()) {  // bounds of the whole map
    const protocol::TileKey k = protocol::tile_key(id);
    const std::array<double, 3> corner{k.x * size, k.y * size, k.z * size};
    for (std::size_t i = 0; i < 3; ++i) {
      const auto low = static_cast<float>(corner[i]);
      const auto high = static_cast<float>(corner[i] + size);
      lo[i] = first ? low : std::min(lo[i], low);
      hi[i] = first ? high : std::max(hi[i], high);
    }
    first = false;
  }
  const auto n_parts = static_cast<std::int32_t>(
      std::max<std::size_t>(1, (tiles.size() + kIndexEntriesPerPart - 1) / kIndexEntriesPerPart));
  for (std::int32_t part = 0; part < n_parts; ++part) {
    tile_index_t m;
    m.utime = realtime_us();
    m.schema = 1;
    m.payload_id = options_.payload_id;
    m.session_id = session_id_;
    m.request_id = request_id;
    m.error = error;
    m.tile_size_m = static_cast<float>(size);
    m.full = full;
    m.part = part;
    m.n_parts = n_parts;
    const std::size_t begin = static_cast<std::size_t>(part) * kIndexEntriesPerPart;
    const std::size_t end = std::min(tiles.size(), begin + kIndexEntriesPerPart);
    for (std::size_t i = begin; i < end; ++i) {
      m.tile_ids.push_back(tiles[i]->id);
      m.versions.push_back(tiles[i]->version);
      m.n_chunks.push_back(tiles[i]->n_segments());
      m.n_points.push_back(tiles[i]->n_points);
    }
    m.n_tiles = static_cast<std::int32_t>(m.tile_ids.size());
    m.total_points = store_.total_points();
    std::copy(lo.begin(), lo.end(), m.bounds_min);
    std::copy(hi.begin(), hi.end(), m.bounds_max);
    sink_.send(m);
    ++counts_.index_published;
  }
}

// Sends queued segments at options_.bytes_per_s: a burst of a whole map would
// overflow the receivers' socket buffers and the Wi-Fi link.
void TilePublisher::send_chunks(Clock::time_point now) {
  const double elapsed =
      last_budget_ == Clock::time_point{} ? 0.0 : std::chrono::duration<double>(now - last_budget_).count();
  last_budget_ = now;
  budget_bytes_ = std::min(budget_bytes_ + elapsed * options_.bytes_per_s, kBurstBytes);
  while (!outgoing_.empty() && budget_bytes_ > 0) {
    const SegmentRef ref = outgoing_.front();
    outgoing_.pop_front();
    const auto queued = queued_.find(ref);
    std::int32_t base = queued->second;
    queued_.erase(queued);
    const EncodedTile* tile = store_.find(ref.tile_id);
    if (tile == nullptr || ref.segment >= tile->n_segments()) continue;
    // The tile may have changed since this was queued: its current segment
    // goes out, with what a holder of `base` lacks at the current version.
    if (base >= tile->version) base = 0;
    budget_bytes_ -= static_cast<double>(tile->frame_bytes(static_cast<std::size_t>(ref.segment)));
    if (options_.drop_fraction > 0 && unit_(drop_rng_) < options_.drop_fraction) {
      ++counts_.chunks_dropped_by_hook;
      continue;
    }
    tile_segment_t m;
    // A segment that cannot be read is not sent: the client asks again, and
    // the error (naming the file) is counted and logged once per session.
    if (const std::string problem = store_.read_frame(*tile, static_cast<std::size_t>(ref.segment), m.data);
        !problem.empty()) {
      ++counts_.segment_read_errors;
      if (session_read_errors_++ == 0) log::error("tile stream: {}", problem);
      continue;
    }
    m.utime = tile->utime;
    m.schema = tile->params.centred ? 3 : 2;  // 3: the origin centred on the tile (tile_codec.hpp)
    m.payload_id = options_.payload_id;
    m.session_id = session_id_;
    m.tile_id = tile->id;
    m.version = tile->version;
    m.base_version = base;
    m.first_segment = static_cast<std::int32_t>(protocol::first_segment_after(tile->segments, base));
    m.segment = ref.segment;
    m.n_segments = tile->n_segments();
    m.n_points = tile->n_points;
    m.tile_size_m = static_cast<float>(tile->params.tile_size_m);
    m.quantum_m = static_cast<float>(tile->params.quantum_m);
    m.size = static_cast<std::int32_t>(m.data.size());
    sink_.send(m);
    ++counts_.chunks_published;
    counts_.chunk_bytes_published += static_cast<std::uint64_t>(m.getEncodedSize());
  }
}

}  // namespace adit::daemon
