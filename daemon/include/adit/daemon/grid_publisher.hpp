#pragma once
// The daemon's side of the live grid's stream (grid_patch_t on GRID), without
// sockets: keeps each patch's newest message (its cells in one zstd frame)
// and, at most once per period, sends the patches that changed since the
// last send, then a share of the others so every patch goes out again within
// `refresh_s`. The refresh is what a client that joins late, or lost a
// datagram, relies on: the stream has no requests. Messages leave through a
// GridPatchSink (the LCM endpoint, or a test).

#include <chrono>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "adit/grid_patch_t.hpp"

namespace adit::daemon {

class GridPatchSink {
 public:
  virtual ~GridPatchSink() = default;
  virtual void send(const grid_patch_t& patch) = 0;
};

// One changed patch from the mapping thread (slam::LiveGrid's values).
struct GridPatchUpdate {
  std::int64_t utime = 0;
  std::int32_t x = 0, y = 0;
  std::int32_t version = 0;
  std::int32_t patches = 0;  // in the whole grid
  float resolution_m = 0.0F;
  std::int32_t patch_cells = 0;
  std::vector<std::int8_t> cells;
};

struct GridPublisherOptions {
  std::string payload_id;
  double period_s = 1.0;
  double refresh_s = 10.0;
};

struct GridPublisherCounts {
  std::uint64_t patches_sent = 0;    // changed and refreshed
  std::uint64_t refreshes_sent = 0;  // of those, sent again unchanged
  std::uint64_t bytes_sent = 0;      // encoded grid_patch_t bytes
};

class GridPublisher {
 public:
  using Clock = std::chrono::steady_clock;

  GridPublisher(GridPublisherOptions options, GridPatchSink& sink);

  // A new session: forgets every patch.
  void reset(std::string session_id);
  // Throws std::runtime_error when zstd cannot compress.
  void update(const GridPatchUpdate& update);
  void tick(Clock::time_point now);

  std::size_t patch_count() const { return patches_.size(); }
  const GridPublisherCounts& counts() const { return counts_; }

 private:
  using Key = std::pair<std::int32_t, std::int32_t>;
  void send(grid_patch_t& message);

  GridPublisherOptions options_;
  GridPatchSink& sink_;
  std::string session_id_;
  std::map<Key, grid_patch_t> patches_;
  std::set<Key> dirty_;
  Key refresh_cursor_{};  // the last patch refreshed
  Clock::time_point last_send_{};
  GridPublisherCounts counts_;
};

}  // namespace adit::daemon
