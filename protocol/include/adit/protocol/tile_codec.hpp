#pragma once
// Map tiles: fixed-size cubes of the map addressed by integer coordinates.
// Points are quantised to a grid inside their tile (uint16 offsets), stored as
// columns (x, y, z, intensity) and compressed as one zstd frame; the frame is
// cut into chunks small enough for one LCM message each.
//
// Encoded tile ("blob"), little-endian:
//   char[4] "ADT1", u16 format (1), u16 flags (0), u32 n_points,
//   f32 tile_size_m, f32 quantum_m, then a zstd frame (with its content
//   checksum) holding
//   u16 qx[n], u16 qy[n], u16 qz[n], u16 intensity[n], sorted by (qx, qy, qz).
// A point is  origin + q * quantum, origin = tile coordinate * tile_size.

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

struct TileParams {
  double tile_size_m = 20.0;
  double quantum_m = 0.001;  // 1 mm: far below a 5 cm voxel; 20 m / 1 mm fits uint16
  int zstd_level = 3;
};
// "" when usable, else why not (tile_size / quantum must fit uint16).
std::string tile_params_problem(const TileParams& params);

inline constexpr std::size_t kTileHeaderBytes = 20;
inline constexpr std::size_t kBytesPerQuantisedPoint = 8;
// A 20 m tile of 5 cm voxels holds ~1 M surface points; 4 M bounds the memory
// a hostile or corrupt header can make a decoder allocate (32 MB).
inline constexpr std::uint32_t kMaxTilePoints = 4'000'000;
// Chunk payload: 48 000 bytes + LCM and message header stays far below 60 KB.
inline constexpr std::size_t kChunkPayloadBytes = 48'000;
inline constexpr std::int32_t kMaxChunksPerTile = 4096;

// Encodes the points of tile `key`; points outside the tile are clamped to its
// faces (the caller bins points with tile_of). `params` must be valid.
std::vector<std::uint8_t> encode_tile(TileKey key, std::span<const MapPoint> points, const TileParams& params);

// Decodes a blob of tile `key` into `out` (replaced). Returns "" or the reason
// the blob is unusable; never throws on bad bytes.
std::string decode_tile(std::span<const std::uint8_t> blob, TileKey key, std::vector<MapPoint>& out);

std::int32_t chunk_count(std::size_t blob_size);
std::span<const std::uint8_t> chunk_of(std::span<const std::uint8_t> blob, std::int32_t index);

}  // namespace adit::protocol
