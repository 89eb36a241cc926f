#pragma once
// The encoded map tiles of one session, each with a version that increases
// whenever the tile changes, cut into segments (protocol/tile_codec.hpp) that
// each remember the version at which they last changed. Owned by the
// publisher thread.

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "adit/protocol/map_point.hpp"
#include "adit/protocol/tile_codec.hpp"

namespace adit::daemon {

struct EncodedTile {
  std::int64_t id = 0;
  std::int32_t version = 0;  // 1 for the first content
  std::int64_t utime = 0;    // when this version was made
  std::int32_t n_points = 0;
  protocol::TileParams params;  // tile size and quantum of its segments
  std::vector<protocol::TileSegment> segments;
  std::int32_t n_segments() const { return static_cast<std::int32_t>(segments.size()); }
};

class TileStore {
 public:
  explicit TileStore(protocol::TileParams params) : params_(params) {}

  // The new whole content of tile `key` (append order): only the segments
  // that changed are re-encoded. The version goes up by one when anything
  // changed; returns false (and keeps the version) when nothing did.
  bool update(protocol::TileKey key, std::span<const protocol::MapPoint> points, std::int64_t utime);
  // Adds a tile encoded earlier (a stored session's tiles/<id>.adt, format 1
  // or 2), as version 1. Returns "", or why the blob is not a usable tile
  // (then nothing is added).
  std::string insert_encoded(std::int64_t id, std::span<const std::uint8_t> blob, std::int64_t utime);
  const EncodedTile* find(std::int64_t id) const;
  const std::map<std::int64_t, EncodedTile>& tiles() const { return tiles_; }
  const protocol::TileParams& params() const { return params_; }
  std::int64_t total_points() const { return total_points_; }

 private:
  protocol::TileParams params_;
  std::map<std::int64_t, EncodedTile> tiles_;
  std::int64_t total_points_ = 0;
};

}  // namespace adit::daemon
