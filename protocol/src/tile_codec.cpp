#include "adit/protocol/tile_codec.hpp"

#include <zstd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>

#include <fmt/format.h>

namespace adit::protocol {
namespace {

constexpr std::int64_t kCoordBias = kTileCoordinateLimit;
constexpr std::int64_t kCoordMask = (std::int64_t{1} << 21) - 1;

template <typename T>
void put(std::vector<std::uint8_t>& out, std::size_t at, T value) {
  std::memcpy(out.data() + at, &value, sizeof(T));  // host is little-endian (x86-64, aarch64)
}
template <typename T>
T get(std::span<const std::uint8_t> in, std::size_t at) {
  T value;
  std::memcpy(&value, in.data() + at, sizeof(T));
  return value;
}

std::uint16_t quantise(double value, double origin, double quantum) {
  const double q = std::round((value - origin) / quantum);
  if (!(q > 0)) return 0;  // also NaN
  return q >= 65535.0 ? std::uint16_t{65535} : static_cast<std::uint16_t>(q);
}

std::int32_t clamp_coordinate(double tiles) {
  const double limit = kTileCoordinateLimit - 1;
  if (!(tiles > -limit)) return static_cast<std::int32_t>(-limit);  // also NaN
  if (tiles > limit) return static_cast<std::int32_t>(limit);
  return static_cast<std::int32_t>(std::floor(tiles));
}

}  // namespace

std::int64_t tile_id(TileKey key) {
  const auto pack = [](std::int32_t c) { return (std::int64_t{c} + kCoordBias) & kCoordMask; };
  return (pack(key.x) << 42) | (pack(key.y) << 21) | pack(key.z);
}

TileKey tile_key(std::int64_t id) {
  const auto unpack = [](std::int64_t bits) { return static_cast<std::int32_t>((bits & kCoordMask) - kCoordBias); };
  return {unpack(id >> 42), unpack(id >> 21), unpack(id)};
}

TileKey tile_of(double x, double y, double z, double tile_size_m) {
  return {clamp_coordinate(x / tile_size_m), clamp_coordinate(y / tile_size_m), clamp_coordinate(z / tile_size_m)};
}

std::string tile_params_problem(const TileParams& params) {
  if (!(params.tile_size_m > 0) || !(params.quantum_m > 0)) return "tile size and quantum must be positive";
  if (params.tile_size_m / params.quantum_m > 65535.0)
    return fmt::format("tile size {} m / quantum {} m exceeds the 65535 steps of a uint16", params.tile_size_m,
                       params.quantum_m);
  if (params.zstd_level < 1 || params.zstd_level > ZSTD_maxCLevel()) return "zstd level out of range";
  return {};
}

std::vector<std::uint8_t> encode_tile(TileKey key, std::span<const MapPoint> points, const TileParams& params) {
  if (const std::string problem = tile_params_problem(params); !problem.empty()) throw std::invalid_argument(problem);
  if (points.size() > kMaxTilePoints) throw std::invalid_argument("too many points for one tile");
  const std::size_t n = points.size();
  const double ox = key.x * params.tile_size_m;
  const double oy = key.y * params.tile_size_m;
  const double oz = key.z * params.tile_size_m;
  // Points are sorted by their quantised (x, y, z): the order inside a tile
  // carries no meaning, and sorted columns compress several times better
  // than the arbitrary order of a voxel hash map (bench_tile_stream).
  std::vector<std::array<std::uint16_t, 4>> quantised(n);
  for (std::size_t i = 0; i < n; ++i) {
    const MapPoint& p = points[i];
    quantised[i] = {quantise(p.x, ox, params.quantum_m), quantise(p.y, oy, params.quantum_m),
                    quantise(p.z, oz, params.quantum_m), quantise(p.intensity, 0.0, 1.0)};
  }
  std::sort(quantised.begin(), quantised.end());
  // Columns compress better than interleaved records: neighbouring values of
  // one axis share their high bytes.
  std::vector<std::uint16_t> columns(4 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t c = 0; c < 4; ++c) columns[c * n + i] = quantised[i][c];
  const std::size_t raw_size = columns.size() * sizeof(std::uint16_t);
  std::vector<std::uint8_t> blob(kTileHeaderBytes + ZSTD_compressBound(raw_size));
  std::memcpy(blob.data(), "ADT1", 4);
  put<std::uint16_t>(blob, 4, 1);
  put<std::uint16_t>(blob, 6, 0);
  put<std::uint32_t>(blob, 8, static_cast<std::uint32_t>(n));
  put<float>(blob, 12, static_cast<float>(params.tile_size_m));
  put<float>(blob, 16, static_cast<float>(params.quantum_m));
  // The frame carries zstd's content checksum: UDP's 16-bit sum is weak and a
  // corrupt tile must be refused, not drawn.
  const std::unique_ptr<ZSTD_CCtx, decltype(&ZSTD_freeCCtx)> context(ZSTD_createCCtx(), &ZSTD_freeCCtx);
  if (!context) throw std::runtime_error("zstd: cannot create a compression context");
  ZSTD_CCtx_setParameter(context.get(), ZSTD_c_compressionLevel, params.zstd_level);
  ZSTD_CCtx_setParameter(context.get(), ZSTD_c_checksumFlag, 1);
  const std::size_t packed = ZSTD_compress2(context.get(), blob.data() + kTileHeaderBytes,
                                            blob.size() - kTileHeaderBytes, columns.data(), raw_size);
  if (ZSTD_isError(packed)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(packed));
  blob.resize(kTileHeaderBytes + packed);
  return blob;
}

std::string decode_tile(std::span<const std::uint8_t> blob, TileKey key, std::vector<MapPoint>& out) {
  out.clear();
  if (blob.size() < kTileHeaderBytes) return "tile shorter than its header";
  if (std::memcmp(blob.data(), "ADT1", 4) != 0) return "tile does not start with ADT1";
  if (get<std::uint16_t>(blob, 4) != 1) return fmt::format("tile format {} is not 1", get<std::uint16_t>(blob, 4));
  const std::uint32_t n = get<std::uint32_t>(blob, 8);
  const TileParams params{get<float>(blob, 12), get<float>(blob, 16)};
  if (n > kMaxTilePoints) return fmt::format("tile claims {} points (limit {})", n, kMaxTilePoints);
  if (const std::string problem = tile_params_problem(params); !problem.empty()) return problem;
  const auto frame = blob.subspan(kTileHeaderBytes);
  const std::size_t raw_size = std::size_t{n} * kBytesPerQuantisedPoint;
  const unsigned long long content = ZSTD_getFrameContentSize(frame.data(), frame.size());
  if (content != raw_size) return "tile's zstd frame size does not match its point count";
  std::vector<std::uint16_t> columns(4 * std::size_t{n});
  const std::size_t got = ZSTD_decompress(columns.data(), raw_size, frame.data(), frame.size());
  if (ZSTD_isError(got)) return std::string("zstd: ") + ZSTD_getErrorName(got);
  if (got != raw_size) return "tile's zstd frame is short";
  const double ox = key.x * params.tile_size_m;
  const double oy = key.y * params.tile_size_m;
  const double oz = key.z * params.tile_size_m;
  out.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    out[i].x = ox + columns[i] * params.quantum_m;
    out[i].y = oy + columns[n + i] * params.quantum_m;
    out[i].z = oz + columns[2 * n + i] * params.quantum_m;
    out[i].intensity = columns[3 * n + i];
  }
  return {};
}

std::int32_t chunk_count(std::size_t blob_size) {
  return static_cast<std::int32_t>(std::max<std::size_t>(1, (blob_size + kChunkPayloadBytes - 1) / kChunkPayloadBytes));
}

std::span<const std::uint8_t> chunk_of(std::span<const std::uint8_t> blob, std::int32_t index) {
  const std::size_t begin = std::min(blob.size(), static_cast<std::size_t>(index) * kChunkPayloadBytes);
  return blob.subspan(begin, std::min(kChunkPayloadBytes, blob.size() - begin));
}

}  // namespace adit::protocol
