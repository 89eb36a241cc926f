#include "adit/daemon/tile_store.hpp"

namespace adit::daemon {

bool TileStore::update(protocol::TileKey key, std::span<const protocol::MapPoint> points, std::int64_t utime) {
  const std::int64_t id = protocol::tile_id(key);
  EncodedTile& tile = tiles_[id];
  tile.id = id;
  tile.params = params_;
  const std::size_t first = protocol::update_segments(key, points, params_, tile.version + 1, tile.segments);
  if (first == tile.segments.size()) return false;
  total_points_ += static_cast<std::int64_t>(points.size()) - tile.n_points;
  tile.version += 1;
  tile.utime = utime;
  tile.n_points = static_cast<std::int32_t>(points.size());
  return true;
}

std::string TileStore::insert_encoded(std::int64_t id, std::span<const std::uint8_t> blob, std::int64_t utime) {
  protocol::TileParams params = params_;
  std::vector<protocol::TileSegment> segments;
  if (std::string problem = protocol::unpack_tile(blob, protocol::tile_key(id), params, segments); !problem.empty())
    return problem;
  std::int64_t n_points = 0;
  for (const protocol::TileSegment& s : segments) n_points += s.n_points;
  EncodedTile& tile = tiles_[id];
  total_points_ += n_points - tile.n_points;
  tile.id = id;
  tile.version = 1;
  tile.utime = utime;
  tile.n_points = static_cast<std::int32_t>(n_points);
  tile.params = params;
  tile.segments = std::move(segments);
  return {};
}

const EncodedTile* TileStore::find(std::int64_t id) const {
  const auto it = tiles_.find(id);
  return it == tiles_.end() ? nullptr : &it->second;
}

}  // namespace adit::daemon
