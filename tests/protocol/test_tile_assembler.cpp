// Reassembly: segments in any order, duplicates, stale and newer versions,
// deltas that bring a held version up to date, and a request for exactly what
// is missing.
#include <gtest/gtest.h>

#include <algorithm>

#include "adit/protocol/tile_assembler.hpp"
#include "adit/protocol/tile_codec.hpp"
#include "adit/tile_segment_t.hpp"

namespace adit::protocol {
namespace {

// A tile as the daemon holds it: its points in append order and its segments.
struct Source {
  TileKey key;
  std::int32_t version = 0;
  std::vector<MapPoint> points;
  std::vector<TileSegment> segments;
  std::int64_t id() const { return tile_id(key); }
  std::int32_t n_segments() const { return static_cast<std::int32_t>(segments.size()); }

  // Appends `n` pseudo-random points: a new version.
  void grow(std::size_t n) {
    std::uint32_t s = 12345u + static_cast<std::uint32_t>(points.size());
    for (std::size_t i = 0; i < n; ++i) {
      s = s * 1664525u + 1013904223u;
      points.push_back({key.x * 20.0 + (s % 20000) * 0.001, key.y * 20.0 + ((s >> 8) % 20000) * 0.001,
                        key.z * 20.0 + ((s >> 16) % 20000) * 0.001, 1.0F, 0});
    }
    update_segments(key, points, {}, ++version, segments);
  }
  // Segment i of the current version, for a holder of `base`.
  tile_segment_t segment(std::int32_t i, std::int32_t base = 0) const {
    tile_segment_t m{};
    m.utime = 1'700'000'000'000'000;
    m.schema = 2;
    m.tile_id = id();
    m.version = version;
    m.base_version = base;
    m.first_segment = static_cast<std::int32_t>(first_segment_after(segments, base));
    m.segment = i;
    m.n_segments = n_segments();
    m.n_points = static_cast<std::int32_t>(points.size());
    m.tile_size_m = 20.0F;
    m.quantum_m = 0.001F;
    m.data = segments[static_cast<std::size_t>(i)].frame;
    m.size = static_cast<std::int32_t>(m.data.size());
    return m;
  }
};

Source make_tile(TileKey key, std::size_t n) {
  Source t{key, 0, {}, {}};
  t.grow(n);
  return t;
}

TEST(TileAssembler, RequestsOnlyTheMissingSegments) {
  const Source tile = make_tile({1, 1, 0}, 6000);
  ASSERT_GE(tile.n_segments(), 4);
  const Source other = make_tile({2, 1, 0}, 100);
  TileAssembler a;
  a.note_index(tile.id(), tile.version, tile.n_segments());
  a.note_index(other.id(), other.version, other.n_segments());
  EXPECT_EQ(a.add_segment(tile.segment(0)), SegmentOutcome::stored);
  EXPECT_EQ(a.add_segment(tile.segment(2)), SegmentOutcome::stored);
  EXPECT_EQ(a.add_segment(tile.segment(2)), SegmentOutcome::duplicate);
  const auto missing = a.missing(100);
  std::vector<std::int32_t> segments;
  for (const auto& m : missing) {
    EXPECT_EQ(m.held_version, 0);  // nothing held yet
    if (m.tile_id == tile.id()) {
      segments.push_back(m.segment);
    } else {
      EXPECT_EQ(m.tile_id, other.id());
      EXPECT_EQ(m.segment, -1);  // nothing of it yet: everything
    }
  }
  std::vector<std::int32_t> expected;
  for (std::int32_t i = 0; i < tile.n_segments(); ++i)
    if (i != 0 && i != 2) expected.push_back(i);
  EXPECT_EQ(segments, expected);
  EXPECT_EQ(missing.size(), expected.size() + 1);
  EXPECT_EQ(a.missing(2).size(), 2u);
  EXPECT_FALSE(a.complete());

  for (std::int32_t i = tile.n_segments() - 1; i >= 0; --i) a.add_segment(tile.segment(i));
  EXPECT_EQ(a.add_segment(other.segment(0)), SegmentOutcome::completed);
  EXPECT_TRUE(a.complete());
  EXPECT_TRUE(a.missing(100).empty());
  EXPECT_EQ(a.points().size(), 6100u);
  EXPECT_EQ(a.segments_have(), a.segments_wanted());
}

TEST(TileAssembler, AHeldVersionIsBroughtUpToDateByTheNewSegmentsOnly) {
  Source tile = make_tile({0, 0, 0}, 3000);  // segments 0..2, the last partly filled
  TileAssembler a;
  for (std::int32_t i = 0; i < tile.n_segments(); ++i) a.add_segment(tile.segment(i));
  ASSERT_TRUE(a.complete());
  const std::int32_t held = tile.version;
  tile.grow(1500);  // fills segment 2, adds 3 and 4
  ASSERT_EQ(tile.n_segments(), 5);
  a.note_index(tile.id(), tile.version, tile.n_segments());
  EXPECT_FALSE(a.complete());
  const auto ask = a.missing(100);
  ASSERT_EQ(ask.size(), 1u);
  EXPECT_EQ(ask[0].held_version, held);
  EXPECT_EQ(ask[0].segment, -1);
  // The daemon's answer: segments changed after the version held.
  const std::int32_t first = static_cast<std::int32_t>(first_segment_after(tile.segments, held));
  EXPECT_EQ(first, 2);
  EXPECT_EQ(a.add_segment(tile.segment(4, held)), SegmentOutcome::stored);
  const auto rest = a.missing(100);  // now it knows exactly which
  ASSERT_EQ(rest.size(), 2u);
  EXPECT_EQ(rest[0].segment, 2);
  EXPECT_EQ(rest[1].segment, 3);
  EXPECT_EQ(a.add_segment(tile.segment(2, held)), SegmentOutcome::stored);
  EXPECT_EQ(a.add_segment(tile.segment(3, held)), SegmentOutcome::completed);
  EXPECT_TRUE(a.complete());
  EXPECT_EQ(a.points().size(), 4500u);
  // What a follower passes on: the tile at its new version, segments 2.. replaced.
  const auto now = a.held(tile.id());
  ASSERT_TRUE(now.has_value());
  EXPECT_EQ(now->version, tile.version);
  EXPECT_EQ(now->replaced_from, 2);
  ASSERT_EQ(now->segments.size(), 5u);
  EXPECT_EQ(now->segments[4].points, 4500u - 4 * 1024u);
  std::vector<MapPoint> last;
  now->segments[4].decode_into(last);
  EXPECT_EQ(last.size(), 4500u - 4 * 1024u);
  EXPECT_EQ(now->points(), 4500u);
  EXPECT_FALSE(a.held(tile_id({9, 9, 9})).has_value());

  // A delta from a base newer than the version held cannot complete it: the
  // client asks for what changed after its own version.
  TileAssembler behind;
  Source t2 = make_tile({0, 0, 1}, 1000);
  for (std::int32_t i = 0; i < t2.n_segments(); ++i) behind.add_segment(t2.segment(i));
  t2.grow(1000);
  const std::int32_t missed = t2.version;
  t2.grow(1000);
  for (std::int32_t i = 0; i < t2.n_segments(); ++i)
    if (t2.segments[static_cast<std::size_t>(i)].version > missed) behind.add_segment(t2.segment(i, missed));
  EXPECT_FALSE(behind.complete());
  const auto need = behind.missing(100);
  ASSERT_EQ(need.size(), 1u);
  EXPECT_EQ(need[0].held_version, 1);
  EXPECT_EQ(need[0].segment, -1);
  // The answer: segment 0 changed after version 1 as well (it was the
  // partial one); segments 1 and 2 are in hand already.
  EXPECT_EQ(behind.add_segment(t2.segment(0, 1)), SegmentOutcome::completed);
  EXPECT_TRUE(behind.complete());
  EXPECT_EQ(behind.points().size(), 3000u);
}

TEST(TileAssembler, NewerVersionsReplacePartialOnesAndOldOnesAreStale) {
  Source tile = make_tile({0, 0, 0}, 3000);
  const Source v1 = tile;
  tile.grow(3000);
  const Source& v2 = tile;
  TileAssembler a;
  a.note_index(v1.id(), 1, v1.n_segments());
  a.add_segment(v1.segment(0));
  EXPECT_EQ(a.add_segment(v2.segment(1)), SegmentOutcome::stored);  // the live stream moved on
  EXPECT_EQ(a.add_segment(v1.segment(1)), SegmentOutcome::stale);
  const auto missing = a.missing(100);
  ASSERT_FALSE(missing.empty());
  for (std::int32_t i = 0; i < v2.n_segments(); ++i) a.add_segment(v2.segment(i));
  EXPECT_TRUE(a.complete());
  EXPECT_EQ(a.add_segment(v1.segment(0)), SegmentOutcome::stale);
  EXPECT_EQ(a.counts().completed, 1u);
  EXPECT_EQ(a.points().size(), 6000u);
}

TEST(TileAssembler, APartlyReceivedVersionKeepsItsUnchangedSegmentsWhenTheTileGrows) {
  Source tile = make_tile({0, 0, 0}, 5000);  // 5 segments, the last partly filled
  TileAssembler a;
  for (std::int32_t i = 0; i < 3; ++i) a.add_segment(tile.segment(i));  // a slow link: 3 of 5 so far
  const std::int32_t partial = tile.version;
  tile.grow(500);  // segment 4 fills up and 5 is new; 0..3 do not change
  ASSERT_EQ(tile.n_segments(), 6);
  EXPECT_EQ(a.add_segment(tile.segment(4, partial)), SegmentOutcome::stored);  // the broadcast: base 1, first 4
  EXPECT_EQ(a.segments_have(), 4u) << "0..2 kept from version 1, and 4";
  EXPECT_EQ(a.add_segment(tile.segment(0)), SegmentOutcome::duplicate);  // an answer (base 0) says what is lacking
  const auto missing = a.missing(100);
  ASSERT_EQ(missing.size(), 2u);
  EXPECT_EQ(missing[0].segment, 3);
  EXPECT_EQ(missing[1].segment, 5);
  EXPECT_EQ(a.add_segment(tile.segment(3)), SegmentOutcome::stored);
  EXPECT_EQ(a.add_segment(tile.segment(5)), SegmentOutcome::completed);
  EXPECT_EQ(a.points().size(), 5500u);
}

TEST(TileAssembler, MalformedSegmentsAreCountedAndIgnored) {
  const Source t = make_tile({0, 0, 0}, 100);
  TileAssembler a;
  auto bad = t.segment(0);
  bad.segment = 5;  // beyond n_segments
  EXPECT_EQ(a.add_segment(bad), SegmentOutcome::malformed);
  bad = t.segment(0);
  bad.size = 3;  // disagrees with the data
  EXPECT_EQ(a.add_segment(bad), SegmentOutcome::malformed);
  bad = t.segment(0);
  bad.base_version = bad.version;  // a delta to its own base
  EXPECT_EQ(a.add_segment(bad), SegmentOutcome::malformed);
  bad = t.segment(0);
  bad.data[bad.data.size() / 2] ^= 0xff;  // corrupt zstd frame
  EXPECT_EQ(a.add_segment(bad), SegmentOutcome::corrupt);  // zstd's checksum catches it
  EXPECT_EQ(a.counts().malformed, 3u);
  EXPECT_FALSE(a.last_error().empty());
  ASSERT_EQ(a.missing(10).size(), 1u);  // asked for again
  EXPECT_EQ(a.add_segment(t.segment(0)), SegmentOutcome::completed);
}

}  // namespace
}  // namespace adit::protocol
