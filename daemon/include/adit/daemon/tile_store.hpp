#pragma once
// The encoded map tiles of one session, each with a version that increases
// whenever the tile changes. Owned by the publisher thread.

#include <cstdint>
#include <map>
#include <span>
#include <vector>

#include "adit/protocol/map_point.hpp"
#include "adit/protocol/tile_codec.hpp"

namespace adit::daemon {

struct EncodedTile {
  std::int64_t id = 0;
  std::int32_t version = 0;  // 1 for the first content
  std::int64_t utime = 0;    // when this version was made
  std::int32_t n_points = 0;
  std::int32_t n_chunks = 0;
  std::vector<std::uint8_t> blob;  // encode_tile() output
};

class TileStore {
 public:
  explicit TileStore(protocol::TileParams params) : params_(params) {}

  // Replaces the content of tile `key`; returns the new version.
  const EncodedTile& update(protocol::TileKey key, std::span<const protocol::MapPoint> points, std::int64_t utime);
  // Adds a tile encoded earlier (a stored session's tiles/<id>.adt), as version 1.
  // False, and nothing added, when the blob's header is not a tile's.
  bool insert_encoded(std::int64_t id, std::vector<std::uint8_t> blob, std::int64_t utime);
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
