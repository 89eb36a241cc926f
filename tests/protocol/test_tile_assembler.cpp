// Reassembly: chunks in any order, duplicates, stale and newer versions, and
// a request for exactly what is missing.
#include <gtest/gtest.h>

#include <algorithm>

#include "adit/protocol/tile_assembler.hpp"
#include "adit/protocol/tile_codec.hpp"
#include "adit/tile_chunk_t.hpp"

namespace adit::protocol {
namespace {

struct Encoded {
  std::int64_t id;
  std::int32_t version;
  std::vector<std::uint8_t> blob;
  std::int32_t n_chunks() const { return chunk_count(blob.size()); }
  tile_chunk_t chunk(std::int32_t i) const {
    tile_chunk_t m;
    m.utime = 1'700'000'000'000'000;
    m.tile_id = id;
    m.version = version;
    m.chunk = i;
    m.n_chunks = n_chunks();
    const auto piece = chunk_of(blob, i);
    m.data.assign(piece.begin(), piece.end());
    m.size = static_cast<std::int32_t>(m.data.size());
    return m;
  }
};

// A tile of pseudo-random points large enough for several chunks.
Encoded make_tile(TileKey key, std::int32_t version, std::size_t n) {
  std::vector<MapPoint> points(n);
  std::uint32_t s = 12345u + static_cast<std::uint32_t>(version);
  for (auto& p : points) {
    s = s * 1664525u + 1013904223u;
    p.x = key.x * 20.0 + (s % 20000) * 0.001;
    p.y = key.y * 20.0 + ((s >> 8) % 20000) * 0.001;
    p.z = key.z * 20.0 + ((s >> 16) % 20000) * 0.001;
  }
  return {tile_id(key), version, encode_tile(key, points, {})};
}

TEST(TileAssembler, RequestsOnlyTheMissingChunks) {
  const Encoded tile = make_tile({1, 1, 0}, 4, 30000);
  ASSERT_GE(tile.n_chunks(), 4);
  const Encoded other = make_tile({2, 1, 0}, 1, 100);
  TileAssembler a;
  a.note_index(tile.id, tile.version, tile.n_chunks());
  a.note_index(other.id, other.version, other.n_chunks());
  EXPECT_EQ(a.add_chunk(tile.chunk(0)), ChunkOutcome::stored);
  EXPECT_EQ(a.add_chunk(tile.chunk(2)), ChunkOutcome::stored);
  EXPECT_EQ(a.add_chunk(tile.chunk(2)), ChunkOutcome::duplicate);
  const auto missing = a.missing(100);
  std::vector<std::int32_t> chunks;
  for (const auto& m : missing) {
    if (m.tile_id == tile.id) {
      EXPECT_EQ(m.version, 4);
      chunks.push_back(m.chunk);
    } else {
      EXPECT_EQ(m.tile_id, other.id);
      EXPECT_EQ(m.chunk, -1);  // nothing of it yet: the whole tile
    }
  }
  std::vector<std::int32_t> expected;
  for (std::int32_t i = 0; i < tile.n_chunks(); ++i)
    if (i != 0 && i != 2) expected.push_back(i);
  EXPECT_EQ(chunks, expected);
  EXPECT_EQ(missing.size(), expected.size() + 1);
  EXPECT_EQ(a.missing(2).size(), 2u);
  EXPECT_FALSE(a.complete());

  for (std::int32_t i = tile.n_chunks() - 1; i >= 0; --i) a.add_chunk(tile.chunk(i));
  EXPECT_EQ(a.add_chunk(other.chunk(0)), ChunkOutcome::completed);
  EXPECT_TRUE(a.complete());
  EXPECT_TRUE(a.missing(100).empty());
  EXPECT_EQ(a.points().size(), 30100u);
  EXPECT_EQ(a.chunks_have(), a.chunks_wanted());
}

TEST(TileAssembler, NewerVersionsReplacePartialOnesAndOldOnesAreStale) {
  const Encoded v1 = make_tile({0, 0, 0}, 1, 20000);
  const Encoded v2 = make_tile({0, 0, 0}, 2, 20000);
  TileAssembler a;
  a.note_index(v1.id, 1, v1.n_chunks());
  a.add_chunk(v1.chunk(0));
  EXPECT_EQ(a.add_chunk(v2.chunk(1)), ChunkOutcome::stored);  // the live stream moved on
  EXPECT_EQ(a.add_chunk(v1.chunk(1)), ChunkOutcome::stale);
  const auto missing = a.missing(100);
  ASSERT_FALSE(missing.empty());
  for (const auto& m : missing) EXPECT_EQ(m.version, 2);
  for (std::int32_t i = 0; i < v2.n_chunks(); ++i) a.add_chunk(v2.chunk(i));
  EXPECT_TRUE(a.complete());
  EXPECT_EQ(a.add_chunk(v1.chunk(0)), ChunkOutcome::stale);
  EXPECT_EQ(a.counts().completed, 1u);
}

TEST(TileAssembler, MalformedChunksAreCountedAndIgnored) {
  const Encoded t = make_tile({0, 0, 0}, 1, 100);
  TileAssembler a;
  auto bad = t.chunk(0);
  bad.chunk = 5;  // beyond n_chunks
  EXPECT_EQ(a.add_chunk(bad), ChunkOutcome::malformed);
  bad = t.chunk(0);
  bad.size = 3;  // disagrees with the data
  EXPECT_EQ(a.add_chunk(bad), ChunkOutcome::malformed);
  bad = t.chunk(0);
  bad.data[bad.data.size() / 2] ^= 0xff;  // corrupt zstd frame
  EXPECT_EQ(a.add_chunk(bad), ChunkOutcome::corrupt);  // zstd's checksum catches it
  EXPECT_EQ(a.counts().malformed, 2u);
  EXPECT_FALSE(a.last_error().empty());
}

}  // namespace
}  // namespace adit::protocol
