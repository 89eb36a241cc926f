// Fuzzes the tile stream's receiving side: the bytes as a tile_segment_t
// message fed to the assembler (which decodes the segment), and the same
// bytes as an encoded tile blob (formats 1 and 2) decoded whole and split into
// segments. Bad input must be refused, never crash.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "adit/protocol/checked_decode.hpp"
#include "adit/protocol/tile_assembler.hpp"
#include "adit/protocol/tile_codec.hpp"
#include "adit/tile_segment_t.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  adit::tile_segment_t segment;
  if (adit::protocol::checked_decode(data, size, segment)) {
    adit::protocol::TileAssembler assembler;
    assembler.note_index(segment.tile_id, segment.version, segment.n_segments);
    assembler.add_segment(segment);
    (void)assembler.missing(16);
    (void)assembler.points();
  }
  const adit::protocol::TileKey key{1, -2, 3};
  std::vector<adit::protocol::MapPoint> points;
  (void)adit::protocol::decode_tile(std::span(data, size), key, points);
  adit::protocol::TileParams params;
  std::vector<adit::protocol::TileSegment> segments;
  (void)adit::protocol::unpack_tile(std::span(data, size), key, params, segments);
  (void)adit::protocol::decode_segment(std::span(data, size), key, 20.0, 0.001, size % 2 == 0, points);
  return 0;
}
