#pragma once
// The daemon's side of the tile stream, without sockets: keeps the session's
// encoded tiles, broadcasts at most once per period the segments of each
// changed tile that changed since its last broadcast, answers tile requests
// (tile, version held, segment or -1) with the segments changed after the
// version held (or the one asked for), and paces segments so receivers keep
// up. Messages leave through a TileSink (the LCM endpoint, or a test).

#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <span>
#include <string>

#include "adit/daemon/tile_store.hpp"
#include "adit/tile_index_t.hpp"
#include "adit/tile_request_t.hpp"
#include "adit/tile_segment_t.hpp"

namespace adit::daemon {

class TileSink {
 public:
  virtual ~TileSink() = default;
  virtual void send(const tile_segment_t& segment) = 0;
  virtual void send(const tile_index_t& index) = 0;
};

struct TilePublisherOptions {
  std::string payload_id;
  protocol::TileParams tiles;
  double period_s = 1.0;        // changed tiles go out at most this often
  double bytes_per_s = 4.0e6;   // segment pacing
  double drop_fraction = 0;     // test hook: segments silently not sent
  std::uint32_t drop_seed = 1;
  // Fills `into` with a stored session's tiles when a client asks for a
  // session other than the one held; returns "" or why it cannot (unknown
  // session, busy mapping). Empty: only the held session is served.
  std::function<std::string(const std::string& session, TileStore& into)> load_session;
};

// "Chunks" are tile_segment_t messages (the names predate segments).
struct TilePublisherCounts {
  std::uint64_t chunks_published = 0;
  std::uint64_t chunks_dropped_by_hook = 0;
  std::uint64_t chunk_bytes_published = 0;  // encoded tile_segment_t bytes
  std::uint64_t index_published = 0;
  std::uint64_t segment_read_errors = 0;  // segments not sent: their file could not be read
  std::uint64_t updates_refused = 0;       // tile updates from a point the tile does not hold
};

class TilePublisher {
 public:
  using Clock = std::chrono::steady_clock;

  TilePublisher(TilePublisherOptions options, TileSink& sink);

  // A new session: forgets every tile and everything queued. With a
  // `spool_dir` (the session's folder), full segments' frames are kept in a
  // file there instead of RAM (TileStore).
  void reset(std::string session_id, const std::filesystem::path& spool_dir = {});
  // The new content of tile `key`, append order (its version goes up by one
  // when it changed): its points from `first_point` on, those before being
  // the ones it held (0: the whole tile). An update that does not fit what
  // the tile holds is counted (updates_refused) and logged once; the tile
  // stays as it was until its next whole content.
  void update(protocol::TileKey key, std::size_t first_point, std::span<const protocol::MapPoint> points,
              std::int64_t utime);
  // A client's request (payload already checked by the caller).
  void answer(const tile_request_t& request);
  // Broadcasts changed tiles when the period is up and sends paced chunks.
  void tick(Clock::time_point now);

  const TileStore& store() const { return store_; }
  const std::string& session_id() const { return session_id_; }
  const TilePublisherCounts& counts() const { return counts_; }
  std::size_t queued_segments() const { return outgoing_.size(); }

 private:
  struct SegmentRef {
    std::int64_t tile_id;
    std::int32_t segment;
    auto operator<=>(const SegmentRef&) const = default;
  };
  // Queues segments [first_segment_after(base), n) of `tile`, or only `only_segment`.
  void queue_segments(const EncodedTile& tile, std::int32_t base, std::int32_t only_segment);
  void send_index(const std::vector<const EncodedTile*>& tiles, bool full, std::int64_t request_id,
                  const std::string& error);
  void send_chunks(Clock::time_point now);

  TilePublisherOptions options_;
  TileSink& sink_;
  std::string session_id_;
  TileStore store_;
  std::set<std::int64_t> dirty_;
  // The version of each tile at its last broadcast: the base of the next one.
  std::map<std::int64_t, std::int32_t> broadcast_version_;
  std::deque<SegmentRef> outgoing_;
  // Queued segments and the base to send each with: the oldest asked for, so
  // that the message serves every client that asked.
  std::map<SegmentRef, std::int32_t> queued_;
  double budget_bytes_;
  Clock::time_point last_budget_{};
  Clock::time_point last_broadcast_{};
  std::mt19937 drop_rng_;
  std::uniform_real_distribution<double> unit_{0.0, 1.0};
  TilePublisherCounts counts_;
  std::uint64_t reported_write_errors_ = 0;  // spool write errors already logged this session
  std::uint64_t session_read_errors_ = 0;    // this session's, the first is logged
};

}  // namespace adit::daemon
