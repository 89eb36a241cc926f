#include "adit/daemon/tile_store.hpp"

#include <cstring>

namespace adit::daemon {

const EncodedTile& TileStore::update(protocol::TileKey key, std::span<const protocol::MapPoint> points,
                                     std::int64_t utime) {
  const std::int64_t id = protocol::tile_id(key);
  EncodedTile& tile = tiles_[id];
  total_points_ += static_cast<std::int64_t>(points.size()) - tile.n_points;
  tile.id = id;
  tile.version += 1;
  tile.utime = utime;
  tile.n_points = static_cast<std::int32_t>(points.size());
  tile.blob = protocol::encode_tile(key, points, params_);
  tile.n_chunks = protocol::chunk_count(tile.blob.size());
  return tile;
}

bool TileStore::insert_encoded(std::int64_t id, std::vector<std::uint8_t> blob, std::int64_t utime) {
  // Header: "ADT1", u16 format, u16 flags, u32 n_points (little-endian), see tile_codec.hpp.
  if (blob.size() < protocol::kTileHeaderBytes || std::memcmp(blob.data(), "ADT1", 4) != 0) return false;
  std::uint32_t n_points = 0;
  for (int i = 3; i >= 0; --i) n_points = (n_points << 8) | blob[8 + static_cast<std::size_t>(i)];
  if (n_points > protocol::kMaxTilePoints) return false;
  EncodedTile& tile = tiles_[id];
  total_points_ += static_cast<std::int64_t>(n_points) - tile.n_points;
  tile.id = id;
  tile.version = 1;
  tile.utime = utime;
  tile.n_points = static_cast<std::int32_t>(n_points);
  tile.blob = std::move(blob);
  tile.n_chunks = protocol::chunk_count(tile.blob.size());
  return true;
}

const EncodedTile* TileStore::find(std::int64_t id) const {
  const auto it = tiles_.find(id);
  return it == tiles_.end() ? nullptr : &it->second;
}

}  // namespace adit::daemon
