#pragma once
// The receiving side of the tile stream: collects chunks per tile version,
// decodes a tile once all its chunks are in, and says what is still missing
// (only that) so a client can ask for it with a tile_request_t.

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "adit/protocol/map_point.hpp"

namespace adit {
class tile_chunk_t;
}

namespace adit::protocol {

enum class ChunkOutcome { stored, completed, duplicate, stale, malformed, corrupt };

struct MissingChunk {
  std::int64_t tile_id = 0;
  std::int32_t version = 0;
  std::int32_t chunk = -1;  // -1: every chunk of that version
};

struct AssemblerCounts {
  std::size_t stored = 0, completed = 0, duplicate = 0, stale = 0, malformed = 0, corrupt = 0;
};

class TileAssembler {
 public:
  // From the tile index: tile `id` exists at `version` in `n_chunks` chunks.
  void note_index(std::int64_t id, std::int32_t version, std::int32_t n_chunks);

  ChunkOutcome add_chunk(const tile_chunk_t& chunk);

  // What is lacking for every known tile to reach its newest known version,
  // at most `limit` entries; a tile with no chunk of that version yet is one
  // entry with chunk -1.
  std::vector<MissingChunk> missing(std::size_t limit) const;
  bool complete() const;
  // Chunks in hand and chunks wanted, over the newest known versions (progress).
  std::size_t chunks_have() const;
  std::size_t chunks_wanted() const;

  // Every decoded tile's points, in tile id order.
  std::vector<MapPoint> points() const;
  std::size_t tile_count() const { return tiles_.size(); }
  const AssemblerCounts& counts() const { return counts_; }
  const std::string& last_error() const { return last_error_; }

 private:
  struct Tile {
    std::int32_t wanted_version = -1;
    std::int32_t wanted_chunks = 0;
    std::int32_t partial_version = -1;
    std::vector<std::vector<std::uint8_t>> parts;
    std::int32_t parts_have = 0;
    std::int32_t done_version = -1;
    std::vector<MapPoint> points;
  };
  ChunkOutcome finish(std::int64_t id, Tile& tile, std::int64_t utime);
  ChunkOutcome count(ChunkOutcome outcome);

  std::map<std::int64_t, Tile> tiles_;
  AssemblerCounts counts_;
  std::string last_error_;
};

}  // namespace adit::protocol
