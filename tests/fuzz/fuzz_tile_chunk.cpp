// Fuzzes the tile stream's receiving side: the bytes as a tile_chunk_t message
// fed to the assembler (which decodes a tile once complete), and the same
// bytes as an encoded tile blob. Bad input must be refused, never crash.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "adit/protocol/checked_decode.hpp"
#include "adit/protocol/tile_assembler.hpp"
#include "adit/protocol/tile_codec.hpp"
#include "adit/tile_chunk_t.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  adit::tile_chunk_t chunk;
  if (adit::protocol::checked_decode(data, size, chunk)) {
    adit::protocol::TileAssembler assembler;
    assembler.note_index(chunk.tile_id, chunk.version, chunk.n_chunks);
    assembler.add_chunk(chunk);
    (void)assembler.missing(16);
  }
  std::vector<adit::protocol::MapPoint> points;
  (void)adit::protocol::decode_tile(std::span(data, size), adit::protocol::TileKey{1, -2, 3}, points);
  return 0;
}
