// Tile ids, quantisation, compression, segments and the stored formats.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <random>

#include "adit/protocol/channels.hpp"
#include "adit/protocol/tile_codec.hpp"
#include "adit/tile_segment_t.hpp"

namespace adit::protocol {
namespace {

std::vector<MapPoint> random_points(TileKey key, double size, std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, size);
  std::vector<MapPoint> points(n);
  for (auto& p : points) {
    p.x = key.x * size + u(rng);
    p.y = key.y * size + u(rng);
    p.z = key.z * size + u(rng);
    p.intensity = static_cast<float>(static_cast<int>(u(rng) * 10) % 256);
  }
  return points;
}

TEST(TileId, PacksAndUnpacksNegativeAndLargeCoordinates) {
  for (const TileKey key : {TileKey{0, 0, 0}, TileKey{-1, 2, -3}, TileKey{kTileCoordinateLimit - 1, -kTileCoordinateLimit, 7}}) {
    EXPECT_EQ(tile_key(tile_id(key)), key);
  }
  EXPECT_NE(tile_id({1, 0, 0}), tile_id({0, 1, 0}));
  EXPECT_NE(tile_id({0, 0, 1}), tile_id({0, 0, -1}));
}

TEST(TileId, PointsFallIntoTheFloorOfTheirCoordinates) {
  EXPECT_EQ(tile_of(0.0, 19.999, 20.0, 20.0), (TileKey{0, 0, 1}));
  EXPECT_EQ(tile_of(-0.001, -20.0, -20.001, 20.0), (TileKey{-1, -1, -2}));
  EXPECT_EQ(tile_of(std::nan(""), 1e30, -1e30, 20.0).y, kTileCoordinateLimit - 1);
}

// Points in a canonical order (the codec sorts them; order carries no meaning).
std::vector<MapPoint> sorted_by_mm(std::vector<MapPoint> points) {
  const auto mm = [](const MapPoint& p) {
    return std::make_tuple(std::lround(p.x * 1000), std::lround(p.y * 1000), std::lround(p.z * 1000), p.intensity);
  };
  std::sort(points.begin(), points.end(), [&](const MapPoint& a, const MapPoint& b) { return mm(a) < mm(b); });
  return points;
}

TEST(TileCodec, RoundTripIsWithinHalfAQuantum) {
  const TileParams params;
  const TileKey key{3, -2, 0};
  const auto points = random_points(key, params.tile_size_m, 5000, 1);
  const auto blob = encode_tile(key, points, params);
  std::vector<MapPoint> back;
  ASSERT_EQ(decode_tile(blob, key, back), "");
  ASSERT_EQ(back.size(), points.size());
  const auto a = sorted_by_mm(points);
  const auto b = sorted_by_mm(back);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(b[i].x, a[i].x, 0.5 * params.quantum_m + 1e-6);
    EXPECT_NEAR(b[i].y, a[i].y, 0.5 * params.quantum_m + 1e-6);
    EXPECT_NEAR(b[i].z, a[i].z, 0.5 * params.quantum_m + 1e-6);
    EXPECT_EQ(b[i].intensity, a[i].intensity);
  }
  // 8 bytes per point before compression; random points barely compress, but
  // the header and frame overhead must stay small.
  EXPECT_LT(blob.size(), points.size() * kBytesPerQuantisedPoint + 200);
}

TEST(TileCodec, TheOrderInsideASegmentDoesNotMatter) {
  const TileKey key{0, 0, 0};
  const TileParams params;
  auto points = random_points(key, 20.0, 2000, 4);
  const auto blob = encode_tile(key, points, params);
  std::reverse(points.begin(), points.begin() + params.segment_points);  // within segment 0
  EXPECT_EQ(encode_tile(key, points, params), blob);
  std::swap(points.front(), points.back());  // across segments: another tile in append order
  EXPECT_NE(encode_tile(key, points, params), blob);
}

TEST(TileSegments, AppendingChangesOnlyTheLastSegmentAndAddsNewOnes) {
  const TileKey key{1, 0, -1};
  const TileParams params;
  const std::size_t S = params.segment_points;
  auto points = random_points(key, 20.0, 3 * S + 100, 5);
  std::vector<TileSegment> segments;
  EXPECT_EQ(update_segments(key, points, params, 1, segments), 0u);
  ASSERT_EQ(segments.size(), 4u);
  EXPECT_EQ(segments[3].n_points, 100u);
  const auto before = segments;
  const auto more = random_points(key, 20.0, 2 * S, 6);
  points.insert(points.end(), more.begin(), more.end());
  EXPECT_EQ(update_segments(key, points, params, 2, segments), 3u);
  ASSERT_EQ(segments.size(), 6u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(segments[i].frame, before[i].frame) << i;
    EXPECT_EQ(segments[i].version, 1);
  }
  for (std::size_t i = 3; i < 6; ++i) EXPECT_EQ(segments[i].version, 2) << i;
  EXPECT_EQ(first_segment_after(segments, 1), 3u);
  EXPECT_EQ(first_segment_after(segments, 2), 6u);
  EXPECT_EQ(first_segment_after(segments, 0), 0u);
  // The same content again: nothing changes.
  EXPECT_EQ(update_segments(key, points, params, 3, segments), segments.size());
  EXPECT_EQ(first_segment_after(segments, 2), 6u);
}

TEST(TileSegments, AChangedOldPointRestampsItsSegmentAndEveryLaterOne) {
  const TileKey key{0, 0, 0};
  const TileParams params;
  auto points = random_points(key, 20.0, 4 * params.segment_points, 7);
  std::vector<TileSegment> segments;
  update_segments(key, points, params, 1, segments);
  points[params.segment_points + 5].x += 0.5;  // in segment 1
  EXPECT_EQ(update_segments(key, points, params, 2, segments), 1u);
  EXPECT_EQ(segments[0].version, 1);
  for (std::size_t i = 1; i < segments.size(); ++i) EXPECT_EQ(segments[i].version, 2);
  // Fewer segments, the rest unchanged: the new last one is restamped so
  // clients learn the new count.
  points.resize(2 * params.segment_points);
  EXPECT_EQ(update_segments(key, points, params, 3, segments), 1u);
  EXPECT_EQ(segments.size(), 2u);
  EXPECT_EQ(segments[1].version, 3);
}

TEST(TileSegments, DecodeToTheTilesPointsInAnyCombination) {
  const TileKey key{-2, 3, 0};
  const TileParams params;
  const auto points = random_points(key, 20.0, 2 * params.segment_points + 17, 8);
  std::vector<TileSegment> segments;
  update_segments(key, points, params, 1, segments);
  std::vector<MapPoint> back;
  for (const TileSegment& s : segments)
    ASSERT_EQ(decode_segment(s.frame, key, params.tile_size_m, params.quantum_m, true, back), "");
  ASSERT_EQ(back.size(), points.size());
  const auto a = sorted_by_mm(points);
  const auto b = sorted_by_mm(back);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(b[i].x, a[i].x, 0.5 * params.quantum_m + 1e-6);
  auto bad = segments[0].frame;
  bad[bad.size() / 2] ^= 0xff;
  std::vector<MapPoint> out;
  EXPECT_NE(decode_segment(bad, key, params.tile_size_m, params.quantum_m, true, out), "");  // zstd's checksum
  EXPECT_NE(decode_segment(std::span(segments[0].frame).first(3), key, 20.0, 0.001, true, out), "");
  EXPECT_NE(decode_segment(segments[0].frame, key, 100.0, 0.001, true, out), "");  // 100 m / 1 mm > uint16
}

TEST(TileCodec, StoredTilesOfTheOldFormatStillLoad) {
  const TileKey key{4, 4, 0};
  const TileParams params;
  const auto points = random_points(key, 20.0, 3000, 9);
  const auto old_blob = encode_tile_format1(key, points, params);
  ASSERT_EQ(old_blob[4], 1);  // format 1
  std::vector<MapPoint> from_old;
  ASSERT_EQ(decode_tile(old_blob, key, from_old), "");
  std::vector<MapPoint> from_new;
  ASSERT_EQ(decode_tile(encode_tile(key, points, params), key, from_new), "");
  const auto a = sorted_by_mm(from_old);
  const auto b = sorted_by_mm(from_new);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(b[i].x, a[i].x, 1e-9);
  // Served to clients as segments (re-cut on load), with the corner origin.
  TileParams read = params;
  std::vector<TileSegment> segments;
  ASSERT_EQ(unpack_tile(old_blob, key, read, segments), "");
  EXPECT_EQ(segments.size(), 3u);
  EXPECT_FALSE(read.centred);
  std::vector<MapPoint> joined;
  for (const TileSegment& s : segments) ASSERT_EQ(decode_segment(s.frame, key, 20.0, 0.001, false, joined), "");
  EXPECT_NEAR(sorted_by_mm(joined).front().x, a.front().x, 1e-9);
  EXPECT_EQ(joined.size(), points.size());
  auto future = old_blob;
  future[4] = 4;
  EXPECT_EQ(decode_tile(future, key, from_old), "tile format 4 is not 1, 2 or 3");
}

// Format 2 (the corner origin, sessions stored before format 3) still loads;
// format 3 keeps points the loop closure moved out of their tile (up to
// 22.7 m for 20 m at 1 mm), where format 2 clamps them to the tile's faces.
TEST(TileCodec, PointsMovedOutOfTheirTileKeepTheirPlaceFromFormat3) {
  const TileKey key{-2, 5, 0};
  TileParams params;
  std::vector<MapPoint> points = random_points(key, params.tile_size_m, 2000, 4);
  for (std::size_t i = 0; i < points.size(); i += 2) {  // half of them moved up to 22 m out, either way
    const double shift = (i % 4 == 0 ? 1.0 : -1.0) * (21.0 + 0.001 * static_cast<double>(i % 1000));
    points[i].x += shift;
    points[i].z -= shift;
  }
  const auto blob = encode_tile(key, points, params);
  ASSERT_EQ(blob[4], 3);
  std::vector<MapPoint> back;
  ASSERT_EQ(decode_tile(blob, key, back), "");
  const auto a = sorted_by_mm(points);
  const auto b = sorted_by_mm(back);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(b[i].x, a[i].x, 0.5 * params.quantum_m + 1e-6);
    EXPECT_NEAR(b[i].z, a[i].z, 0.5 * params.quantum_m + 1e-6);
  }
  // A decoder's float parameters give the same whole steps of margin: the
  // origins differ only by the float quantum's rounding times the 22 767 steps
  // (1.1 µm), far below the quantum (an off-by-one step would be 1 mm).
  TileParams f = params;
  f.tile_size_m = static_cast<float>(params.tile_size_m);
  f.quantum_m = static_cast<float>(params.quantum_m);
  EXPECT_NEAR(quantisation_origin(key.x, f), quantisation_origin(key.x, params), 0.01 * params.quantum_m);
  EXPECT_NEAR(quantisation_origin(key.x, params), -40.0 - 22.767, 1e-9);

  params.centred = false;  // format 2
  const auto old_blob = encode_tile(key, points, params);
  ASSERT_EQ(old_blob[4], 2);
  ASSERT_EQ(decode_tile(old_blob, key, back), "");
  // The points moved below the tile's corner in x (a quarter of them) are on its face.
  const double lo = key.x * params.tile_size_m;
  EXPECT_EQ(std::count_if(back.begin(), back.end(), [&](const MapPoint& p) { return p.x < lo - 1e-9; }), 0);
  EXPECT_EQ(std::count_if(back.begin(), back.end(), [&](const MapPoint& p) { return std::abs(p.x - lo) < 1e-9; }),
            static_cast<long>(points.size() / 4));
}

TEST(TileCodec, RejectsParametersThatDoNotFitUint16) {
  EXPECT_EQ(tile_params_problem({}), "");
  EXPECT_NE(tile_params_problem({100.0, 0.001, 3, 1024}), "");
  EXPECT_NE(tile_params_problem({20.0, 0.0, 3, 1024}), "");
  EXPECT_NE(tile_params_problem({20.0, 0.001, 3, kMaxSegmentPoints + 1}), "");
  EXPECT_NE(tile_params_problem({20.0, 0.001, 3, 0}), "");
  EXPECT_THROW(encode_tile({}, {}, {100.0, 0.001, 3, 1024}), std::invalid_argument);
}

TEST(TileCodec, CorruptBlobsAreRejectedWithAReason) {
  const TileKey key{0, 0, 0};
  auto blob = encode_tile(key, random_points(key, 20.0, 100, 2), {});
  std::vector<MapPoint> out;
  EXPECT_NE(decode_tile(std::span(blob).first(10), key, out), "");
  auto bad_magic = blob;
  bad_magic[0] = 'X';
  EXPECT_NE(decode_tile(bad_magic, key, out), "");
  auto bad_count = blob;
  bad_count[8] ^= 0x01;  // claims another point count than the frame holds
  EXPECT_NE(decode_tile(bad_count, key, out), "");
  auto huge = blob;
  huge[11] = 0x7f;
  EXPECT_NE(decode_tile(huge, key, out), "");
  auto truncated = blob;
  truncated.resize(blob.size() - 5);
  EXPECT_NE(decode_tile(truncated, key, out), "");
  auto bad_segments = blob;
  bad_segments[24] = 7;  // segment count disagrees with the point count
  EXPECT_NE(decode_tile(bad_segments, key, out), "");
  auto bad_table = blob;
  bad_table[28] ^= 0x10;  // segment 0's byte count
  EXPECT_NE(decode_tile(bad_table, key, out), "");
  auto short_table = blob;
  short_table.resize(kTileHeaderBytesFormat2 + 2);
  EXPECT_NE(decode_tile(short_table, key, out), "");
  EXPECT_TRUE(out.empty());
}

TEST(TileSegments, EverySegmentMessageStaysBelow60KB) {
  const TileKey key{0, 0, 0};
  TileParams params;
  params.segment_points = kMaxSegmentPoints;  // the largest, of random points (barely compressible)
  const auto points = random_points(key, 20.0, 40000, 3);
  std::vector<TileSegment> segments;
  update_segments(key, points, params, 1, segments);
  ASSERT_EQ(segments.size(), 10u);
  for (const TileSegment& s : segments) {
    ASSERT_LE(s.frame.size(), kChunkPayloadBytes);
    tile_segment_t m{};
    m.payload_id = std::string(kMaxPayloadIdLength, 'p');
    m.session_id = std::string(64, 's');
    m.data = s.frame;
    m.size = static_cast<std::int32_t>(m.data.size());
    EXPECT_LT(static_cast<std::size_t>(m.getEncodedSize()), kMaxMessageBytes);
  }
  std::vector<TileSegment> empty;
  update_segments(key, {}, params, 1, empty);
  EXPECT_EQ(empty.size(), 1u);  // an empty tile is one empty segment
  EXPECT_EQ(empty[0].n_points, 0u);
}

TEST(Channels, CarryThePayloadPrefixAndFitLcmsLimit) {
  EXPECT_EQ(channel_name("drone-7", Channel::pose), "ADIT/drone-7/POSE");
  const std::string longest(kMaxPayloadIdLength, 'x');
  EXPECT_EQ(payload_id_problem(longest), "");
  EXPECT_LE(channel_name(longest, Channel::tile_request).size(), 63u);
  EXPECT_NE(payload_id_problem(longest + "x"), "");
  EXPECT_NE(payload_id_problem(""), "");
  EXPECT_NE(payload_id_problem("a/b"), "");
}

}  // namespace
}  // namespace adit::protocol
