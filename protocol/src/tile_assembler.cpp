#include "adit/protocol/tile_assembler.hpp"

#include <fmt/format.h>

#include "adit/protocol/tile_codec.hpp"
#include "adit/tile_chunk_t.hpp"

namespace adit::protocol {

void TileAssembler::note_index(std::int64_t id, std::int32_t version, std::int32_t n_chunks) {
  if (version < 0 || n_chunks < 1 || n_chunks > kMaxChunksPerTile) return;
  Tile& tile = tiles_[id];
  if (version > tile.wanted_version) {
    tile.wanted_version = version;
    tile.wanted_chunks = n_chunks;
  }
}

ChunkOutcome TileAssembler::count(ChunkOutcome outcome) {
  switch (outcome) {
    case ChunkOutcome::stored: ++counts_.stored; break;
    case ChunkOutcome::completed: ++counts_.completed; break;
    case ChunkOutcome::duplicate: ++counts_.duplicate; break;
    case ChunkOutcome::stale: ++counts_.stale; break;
    case ChunkOutcome::malformed: ++counts_.malformed; break;
    case ChunkOutcome::corrupt: ++counts_.corrupt; break;
  }
  return outcome;
}

ChunkOutcome TileAssembler::add_chunk(const tile_chunk_t& chunk) {
  const bool shape_ok = chunk.version >= 0 && chunk.n_chunks >= 1 && chunk.n_chunks <= kMaxChunksPerTile &&
                        chunk.chunk >= 0 && chunk.chunk < chunk.n_chunks && chunk.size > 0 &&
                        static_cast<std::size_t>(chunk.size) == chunk.data.size() &&
                        chunk.data.size() <= kChunkPayloadBytes;
  if (!shape_ok) {
    last_error_ = fmt::format("tile {} chunk {}/{} of {} bytes is malformed", chunk.tile_id, chunk.chunk,
                              chunk.n_chunks, chunk.size);
    return count(ChunkOutcome::malformed);
  }
  Tile& tile = tiles_[chunk.tile_id];
  if (chunk.version <= tile.done_version || chunk.version < tile.partial_version) return count(ChunkOutcome::stale);
  if (chunk.version > tile.wanted_version) {  // the live stream ran ahead of the index
    tile.wanted_version = chunk.version;
    tile.wanted_chunks = chunk.n_chunks;
  }
  if (chunk.version > tile.partial_version) {
    tile.partial_version = chunk.version;
    tile.parts.assign(static_cast<std::size_t>(chunk.n_chunks), {});
    tile.parts_have = 0;
  }
  if (static_cast<std::size_t>(chunk.n_chunks) != tile.parts.size()) {
    last_error_ = fmt::format("tile {} version {} changed its chunk count", chunk.tile_id, chunk.version);
    return count(ChunkOutcome::malformed);
  }
  auto& part = tile.parts[static_cast<std::size_t>(chunk.chunk)];
  if (!part.empty()) return count(ChunkOutcome::duplicate);
  part.assign(chunk.data.begin(), chunk.data.end());
  ++tile.parts_have;
  if (tile.parts_have < chunk.n_chunks) return count(ChunkOutcome::stored);
  return count(finish(chunk.tile_id, tile, chunk.utime));
}

ChunkOutcome TileAssembler::finish(std::int64_t id, Tile& tile, std::int64_t utime) {
  std::vector<std::uint8_t> blob;
  for (const auto& part : tile.parts) blob.insert(blob.end(), part.begin(), part.end());
  const std::int32_t version = tile.partial_version;
  tile.parts.clear();
  tile.parts_have = 0;
  tile.partial_version = -1;
  std::vector<MapPoint> points;
  if (const std::string error = decode_tile(blob, tile_key(id), points); !error.empty()) {
    // Asking again for the same bytes would not help; the version is skipped
    // until a newer one arrives.
    last_error_ = fmt::format("tile {} version {}: {}", id, version, error);
    tile.done_version = version;
    return ChunkOutcome::corrupt;
  }
  for (MapPoint& p : points) p.time = static_cast<double>(utime) * 1e-6;
  tile.points = std::move(points);
  tile.done_version = version;
  return ChunkOutcome::completed;
}

std::vector<MissingChunk> TileAssembler::missing(std::size_t limit) const {
  std::vector<MissingChunk> out;
  for (const auto& [id, tile] : tiles_) {
    if (tile.wanted_version <= tile.done_version) continue;
    if (tile.partial_version != tile.wanted_version) {
      if (out.size() >= limit) return out;
      out.push_back({id, tile.wanted_version, -1});
      continue;
    }
    for (std::size_t i = 0; i < tile.parts.size(); ++i) {
      if (!tile.parts[i].empty()) continue;
      if (out.size() >= limit) return out;
      out.push_back({id, tile.wanted_version, static_cast<std::int32_t>(i)});
    }
  }
  return out;
}

bool TileAssembler::complete() const {
  for (const auto& [id, tile] : tiles_)
    if (tile.wanted_version > tile.done_version) return false;
  return true;
}

std::size_t TileAssembler::chunks_wanted() const {
  std::size_t n = 0;
  for (const auto& [id, tile] : tiles_) n += static_cast<std::size_t>(tile.wanted_chunks);
  return n;
}

std::size_t TileAssembler::chunks_have() const {
  std::size_t n = 0;
  for (const auto& [id, tile] : tiles_) {
    if (tile.done_version >= tile.wanted_version) n += static_cast<std::size_t>(tile.wanted_chunks);
    else if (tile.partial_version == tile.wanted_version) n += static_cast<std::size_t>(tile.parts_have);
  }
  return n;
}

std::vector<MapPoint> TileAssembler::points() const {
  std::vector<MapPoint> out;
  for (const auto& [id, tile] : tiles_) out.insert(out.end(), tile.points.begin(), tile.points.end());
  return out;
}

}  // namespace adit::protocol
