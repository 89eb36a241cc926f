// Tile ids, quantisation, compression and chunking.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <random>

#include "adit/protocol/channels.hpp"
#include "adit/protocol/tile_codec.hpp"
#include "adit/tile_chunk_t.hpp"

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

TEST(TileCodec, TheEncodingDoesNotDependOnThePointOrder) {
  const TileKey key{0, 0, 0};
  auto points = random_points(key, 20.0, 2000, 4);
  const auto blob = encode_tile(key, points, {});
  std::reverse(points.begin(), points.end());
  EXPECT_EQ(encode_tile(key, points, {}), blob);
}

TEST(TileCodec, RejectsParametersThatDoNotFitUint16) {
  EXPECT_EQ(tile_params_problem({}), "");
  EXPECT_NE(tile_params_problem({100.0, 0.001, 3}), "");
  EXPECT_NE(tile_params_problem({20.0, 0.0, 3}), "");
  EXPECT_THROW(encode_tile({}, {}, {100.0, 0.001, 3}), std::invalid_argument);
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
  EXPECT_TRUE(out.empty());
}

TEST(TileChunks, EveryChunkMessageStaysBelow60KB) {
  const TileKey key{0, 0, 0};
  const auto blob = encode_tile(key, random_points(key, 20.0, 40000, 3), {});  // ~320 KB
  const std::int32_t n = chunk_count(blob.size());
  ASSERT_GE(n, 6);
  std::vector<std::uint8_t> joined;
  for (std::int32_t i = 0; i < n; ++i) {
    const auto piece = chunk_of(blob, i);
    tile_chunk_t m;
    m.payload_id = std::string(kMaxPayloadIdLength, 'p');
    m.session_id = std::string(64, 's');
    m.n_chunks = n;
    m.chunk = i;
    m.data.assign(piece.begin(), piece.end());
    m.size = static_cast<std::int32_t>(m.data.size());
    EXPECT_LT(static_cast<std::size_t>(m.getEncodedSize()), kMaxMessageBytes);
    joined.insert(joined.end(), piece.begin(), piece.end());
  }
  EXPECT_EQ(joined, blob);
  EXPECT_EQ(chunk_count(0), 1);
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
