#include "adit/daemon/tile_store.hpp"

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

const EncodedTile* TileStore::find(std::int64_t id) const {
  const auto it = tiles_.find(id);
  return it == tiles_.end() ? nullptr : &it->second;
}

}  // namespace adit::daemon
