#pragma once
// Map tiles: fixed-size cubes of the map addressed by integer coordinates.
// Points are quantised to a grid inside their tile (uint16 offsets) and
// stored as columns (x, y, z, intensity) in zstd frames.
//
// Tiles only grow: the mapper appends confirmed points and never moves old
// ones. So a tile's points, in the order they were appended, are cut into
// *segments* of a fixed point count (TileParams::segment_points); each
// segment is one independently compressed zstd frame, sorted inside (order
// carries no meaning there, and sorted columns compress several times better).
// Appending points changes only the last segment (and adds new ones), so the
// stream sends a changed tile's new segments, not the whole tile.
//
// Segment frame: zstd frame (with its content checksum) holding
//   u16 qx[n], u16 qy[n], u16 qz[n], u16 intensity[n], sorted by (qx, qy, qz);
// n = segment_points except for the last segment. A point is
// origin + q * quantum. From format 3 (segments: tile_segment_t schema 3) the
// uint16 span is centred on the tile: origin = tile coordinate * tile_size −
// m * quantum, m = (65535 − tile_size / quantum) / 2 whole steps (22 767 for
// 20 m at 1 mm), so a point the loop closure moved out of its tile by up to
// m * quantum (22.7 m) keeps its place (docs/LOOPS.md, "Live tiles"). Formats
// 1 and 2 (schema 2) put the origin at the tile's lowest corner.
//
// Encoded tile ("blob", tiles/<id>.adt), little-endian, format 3 (2: the
// same bytes with the origin at the corner):
//   char[4] "ADT1", u16 format (3), u16 flags (0), u32 n_points,
//   f32 tile_size_m, f32 quantum_m, u32 segment_points, u32 n_segments,
//   u32 frame_bytes[n_segments], then the segments' frames in order.
// Format 1 (before segments; still decoded): the same first 20 bytes with
// format 1, then one zstd frame of every point sorted.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "adit/protocol/map_point.hpp"

namespace adit::protocol {

struct TileKey {
  std::int32_t x = 0;
  std::int32_t y = 0;
  std::int32_t z = 0;
  auto operator<=>(const TileKey&) const = default;
};

// Tile coordinates are 21-bit signed (±2^20 tiles, ±20 000 km at 20 m).
inline constexpr std::int32_t kTileCoordinateLimit = 1 << 20;
// Packs (x, y, z) + 2^20 into 21 bits each: x in bits 42..62, y 21..41, z 0..20.
std::int64_t tile_id(TileKey key);
TileKey tile_key(std::int64_t id);
// The tile holding a point; coordinates beyond the limit are clamped.
TileKey tile_of(double x, double y, double z, double tile_size_m);

inline constexpr std::size_t kBytesPerQuantisedPoint = 8;
// A segment of at most 4096 points is at most 32 KB raw (zstd's bound adds
// < 1 %), so it always fits one message's 48 000-byte payload.
inline constexpr std::uint32_t kMaxSegmentPoints = 4096;
inline constexpr std::uint32_t kMinSegmentPoints = 64;

struct TileParams {
  double tile_size_m = 20.0;
  double quantum_m = 0.001;  // 1 mm: far below a 5 cm voxel; 20 m / 1 mm fits uint16
  int zstd_level = 3;
  // Points per segment: the stream re-sends a changed tile's last segment
  // whole, so smaller is cheaper per update, larger compresses better
  // (bench_tile_stream measures the trade-off; 1024 was the cheapest).
  std::uint32_t segment_points = 1024;
  // The uint16 span centred on the tile (format 3), else from its corner
  // (formats 1 and 2, read from stored sessions).
  bool centred = true;
};
// The corner of the quantisation grid of tile coordinate `c` (one axis).
double quantisation_origin(std::int32_t c, const TileParams& params);
// "" when usable, else why not (tile_size / quantum must fit uint16, segment size in range).
std::string tile_params_problem(const TileParams& params);

inline constexpr std::size_t kTileHeaderBytes = 20;        // format 1 and the start of format 2
inline constexpr std::size_t kTileHeaderBytesFormat2 = 28;  // + segment_points, n_segments
inline constexpr std::uint16_t kTileFormat = 3;  // 2 when !TileParams::centred
// A 20 m tile of 5 cm voxels holds ~1 M surface points; 4 M bounds the memory
// a hostile or corrupt header can make a decoder allocate (32 MB).
inline constexpr std::uint32_t kMaxTilePoints = 4'000'000;
// Segment payload per message: 48 000 bytes + LCM and message header stays far below 60 KB.
inline constexpr std::size_t kChunkPayloadBytes = 48'000;
// Segments of a tile: kMaxTilePoints / kMinSegmentPoints.
inline constexpr std::int32_t kMaxSegmentsPerTile = 62'500;

// One segment of a tile: points [index * segment_points, + n_points) of the
// tile's append order, as one zstd frame.
struct TileSegment {
  std::int32_t version = 0;        // the tile version at which this segment last changed
  std::uint64_t content_hash = 0;  // of its quantised points in append order: change detection
  std::uint32_t n_points = 0;
  std::vector<std::uint8_t> frame;
};

// Brings `segments` (those of tile `key`'s previous content, or empty) to the
// new content `points` (append order) at tile version `version`. Segments
// whose quantised points are unchanged are kept as they are; from the first
// changed one on, every segment is re-encoded and stamped `version`, so the
// segments changed after any version form a suffix (what a client lacks is
// always segments [first, n)). Returns that first changed index (== size when
// nothing changed). Points beyond the quantisation span are clamped to its
// faces.
// `params` must be valid; throws std::invalid_argument for too many points.
std::size_t update_segments(TileKey key, std::span<const MapPoint> points, const TileParams& params,
                            std::int32_t version, std::vector<TileSegment>& segments);

// The same for content whose first `first_point` points are those `segments`
// hold and `tail` follows them (what a map tile gained since its last update),
// so an update costs the tail, not the tile. Segments before the one holding
// `first_point` are kept unread; that segment's earlier points are decoded
// from its frame, which must be in RAM (`frame` set) unless `first_point` is
// a segment boundary. Returns "" with the first changed index in `first`, or
// why not (then `segments` are untouched): `first_point` beyond the points
// held, content that would shrink, an unreadable frame, too many points.
std::string append_segments(TileKey key, std::size_t first_point, std::span<const MapPoint> tail,
                            const TileParams& params, std::int32_t version, std::vector<TileSegment>& segments,
                            std::size_t& first);

// The first segment changed after `held_version`: a client holding the tile
// complete at that version lacks exactly segments [first, size).
std::size_t first_segment_after(std::span<const TileSegment> segments, std::int32_t held_version);

// Decodes one segment frame of tile `key` and appends its points to `out`;
// `centred`: the segment's origin (tile_segment_t schema 3, format 3).
// Returns "" or the reason the frame is unusable; never throws on bad bytes.
std::string decode_segment(std::span<const std::uint8_t> frame, TileKey key, double tile_size_m, double quantum_m,
                           bool centred, std::vector<MapPoint>& out);

// The blob of a tile (format 3, or 2 when !params.centred) from its segments.
std::vector<std::uint8_t> pack_tile(const TileParams& params, std::span<const TileSegment> segments);
// Encodes the points of tile `key` (append order) as a blob (pack_tile's format).
std::vector<std::uint8_t> encode_tile(TileKey key, std::span<const MapPoint> points, const TileParams& params);
// The old whole-tile format 1 (one frame of every point sorted): kept to test
// that stored sessions of that format still load, and as the bandwidth baseline.
std::vector<std::uint8_t> encode_tile_format1(TileKey key, std::span<const MapPoint> points, const TileParams& params);

// Splits a blob of tile `key` into its segments (every segment version 1) and
// reads its tile size and quantum into `params`. A format-1 blob is decoded
// and re-cut into segments of `params.segment_points`. Returns "" or the
// reason the blob is unusable; never throws on bad bytes.
std::string unpack_tile(std::span<const std::uint8_t> blob, TileKey key, TileParams& params,
                        std::vector<TileSegment>& segments);

// Decodes a blob (format 1, 2 or 3) of tile `key` into `out` (replaced).
// Returns "" or the reason the blob is unusable; never throws on bad bytes.
std::string decode_tile(std::span<const std::uint8_t> blob, TileKey key, std::vector<MapPoint>& out);

}  // namespace adit::protocol
