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

double quantisation_origin(std::int32_t c, const TileParams& params) {
  const double corner = c * params.tile_size_m;
  if (!params.centred) return corner;
  // Whole steps, from the rounded step count: an encoder's double and a
  // decoder's float parameters give the same origin.
  const long long steps = std::llround(params.tile_size_m / params.quantum_m);
  const long long margin = std::max(0LL, (65535LL - steps) / 2);
  return corner - static_cast<double>(margin) * params.quantum_m;
}

std::string tile_params_problem(const TileParams& params) {
  if (!(params.tile_size_m > 0) || !(params.quantum_m > 0)) return "tile size and quantum must be positive";
  if (params.tile_size_m / params.quantum_m > 65535.0)
    return fmt::format("tile size {} m / quantum {} m exceeds the 65535 steps of a uint16", params.tile_size_m,
                       params.quantum_m);
  if (params.zstd_level < 1 || params.zstd_level > ZSTD_maxCLevel()) return "zstd level out of range";
  if (params.segment_points < kMinSegmentPoints || params.segment_points > kMaxSegmentPoints)
    return fmt::format("{} points per segment is outside {}..{}", params.segment_points, kMinSegmentPoints,
                       kMaxSegmentPoints);
  return {};
}

namespace {

using Quantised = std::array<std::uint16_t, 4>;  // qx, qy, qz, intensity

std::vector<Quantised> quantise_tile(TileKey key, std::span<const MapPoint> points, const TileParams& params) {
  const double ox = quantisation_origin(key.x, params);
  const double oy = quantisation_origin(key.y, params);
  const double oz = quantisation_origin(key.z, params);
  std::vector<Quantised> out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const MapPoint& p = points[i];
    out[i] = {quantise(p.x, ox, params.quantum_m), quantise(p.y, oy, params.quantum_m),
              quantise(p.z, oz, params.quantum_m), quantise(p.intensity, 0.0, 1.0)};
  }
  return out;
}

// 64-bit hash of quantised points in their order (a multiply-xorshift mix in
// the style of MurmurHash3's finaliser): detects a segment whose content
// changed; not a defence against an adversary, the data is our own.
std::uint64_t content_hash(std::span<const Quantised> points) {
  std::uint64_t h = 0x9E3779B97F4A7C15ULL ^ points.size();
  for (const Quantised& q : points) {
    std::uint64_t w = 0;
    std::memcpy(&w, q.data(), sizeof(w));
    h ^= w * 0xC2B2AE3D27D4EB4FULL;
    h = ((h << 31) | (h >> 33)) * 0x9E3779B97F4A7C15ULL;
  }
  h ^= h >> 33;
  h *= 0xFF51AFD7ED558CCDULL;
  h ^= h >> 33;
  return h;
}

using CompressionContext = std::unique_ptr<ZSTD_CCtx, decltype(&ZSTD_freeCCtx)>;

CompressionContext make_context(const TileParams& params) {
  CompressionContext context(ZSTD_createCCtx(), &ZSTD_freeCCtx);
  if (!context) throw std::runtime_error("zstd: cannot create a compression context");
  ZSTD_CCtx_setParameter(context.get(), ZSTD_c_compressionLevel, params.zstd_level);
  // The frame carries zstd's content checksum: UDP's 16-bit sum is weak and a
  // corrupt tile must be refused, not drawn.
  ZSTD_CCtx_setParameter(context.get(), ZSTD_c_checksumFlag, 1);
  return context;
}

// Sorts `points` and compresses them as columns into one zstd frame.
std::vector<std::uint8_t> compress_points(std::vector<Quantised> points, ZSTD_CCtx* context) {
  // Sorted points compress several times better than the arbitrary order of
  // a voxel hash map (bench_tile_stream); columns better than interleaved
  // records: neighbouring values of one axis share their high bytes.
  std::sort(points.begin(), points.end());
  const std::size_t n = points.size();
  std::vector<std::uint16_t> columns(4 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t c = 0; c < 4; ++c) columns[c * n + i] = points[i][c];
  const std::size_t raw_size = columns.size() * sizeof(std::uint16_t);
  std::vector<std::uint8_t> frame(ZSTD_compressBound(raw_size));
  const std::size_t packed = ZSTD_compress2(context, frame.data(), frame.size(), columns.data(), raw_size);
  if (ZSTD_isError(packed)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(packed));
  frame.resize(packed);
  return frame;
}

// Decompresses a frame of exactly `n` quantised points (columns) into `out` (appended).
std::string decompress_points(std::span<const std::uint8_t> frame, std::size_t n, TileKey key, const TileParams& params,
                              std::vector<MapPoint>& out) {
  const double quantum_m = params.quantum_m;
  const std::size_t raw_size = n * kBytesPerQuantisedPoint;
  const unsigned long long content = ZSTD_getFrameContentSize(frame.data(), frame.size());
  if (content != raw_size) return "zstd frame size does not match its point count";
  std::vector<std::uint16_t> columns(4 * n);
  const std::size_t got = ZSTD_decompress(columns.data(), raw_size, frame.data(), frame.size());
  if (ZSTD_isError(got)) return std::string("zstd: ") + ZSTD_getErrorName(got);
  if (got != raw_size) return "zstd frame is short";
  const double ox = quantisation_origin(key.x, params);
  const double oy = quantisation_origin(key.y, params);
  const double oz = quantisation_origin(key.z, params);
  const std::size_t base = out.size();
  out.resize(base + n);
  for (std::size_t i = 0; i < n; ++i) {
    MapPoint& p = out[base + i];
    p.x = ox + columns[i] * quantum_m;
    p.y = oy + columns[n + i] * quantum_m;
    p.z = oz + columns[2 * n + i] * quantum_m;
    p.intensity = columns[3 * n + i];
  }
  return {};
}

std::size_t segment_count(std::size_t n_points, std::uint32_t segment_points) {
  return std::max<std::size_t>(1, (n_points + segment_points - 1) / segment_points);
}

// Reads the 20 bytes common to every format (and format 2's and 3's 8 more);
// "" or why the header is unusable.
std::string read_header(std::span<const std::uint8_t> blob, std::uint16_t& format, std::uint32_t& n,
                        TileParams& params) {
  if (blob.size() < kTileHeaderBytes) return "tile shorter than its header";
  if (std::memcmp(blob.data(), "ADT1", 4) != 0) return "tile does not start with ADT1";
  format = get<std::uint16_t>(blob, 4);
  if (format < 1 || format > 3) return fmt::format("tile format {} is not 1, 2 or 3", format);
  params.centred = format == 3;
  n = get<std::uint32_t>(blob, 8);
  params.tile_size_m = get<float>(blob, 12);
  params.quantum_m = get<float>(blob, 16);
  if (n > kMaxTilePoints) return fmt::format("tile claims {} points (limit {})", n, kMaxTilePoints);
  if (format >= 2) {
    if (blob.size() < kTileHeaderBytesFormat2) return fmt::format("tile shorter than its format-{} header", format);
    params.segment_points = get<std::uint32_t>(blob, 20);
  }
  return tile_params_problem(params);
}

}  // namespace

std::size_t update_segments(TileKey key, std::span<const MapPoint> points, const TileParams& params,
                            std::int32_t version, std::vector<TileSegment>& segments) {
  if (const std::string problem = tile_params_problem(params); !problem.empty()) throw std::invalid_argument(problem);
  if (points.size() > kMaxTilePoints) throw std::invalid_argument("too many points for one tile");
  const std::vector<Quantised> quantised = quantise_tile(key, points, params);
  const std::size_t size = params.segment_points;
  const std::size_t n_segments = segment_count(quantised.size(), params.segment_points);
  std::size_t first = std::min(n_segments, segments.size());
  std::vector<std::uint64_t> hashes(n_segments);
  for (std::size_t s = 0; s < n_segments; ++s) {
    const std::size_t begin = std::min(quantised.size(), s * size);
    const std::size_t count = std::min(size, quantised.size() - begin);
    hashes[s] = content_hash(std::span(quantised).subspan(begin, count));
    if (s < first && (segments[s].n_points != count || segments[s].content_hash != hashes[s])) first = s;
  }
  // A tile that lost its last segments while the rest stayed: its new last
  // segment is re-sent so that clients learn the new segment count.
  if (first == n_segments && segments.size() > n_segments) first = n_segments - 1;
  segments.resize(n_segments);
  if (first == n_segments) return first;
  const CompressionContext context = make_context(params);
  for (std::size_t s = first; s < n_segments; ++s) {
    const std::size_t begin = std::min(quantised.size(), s * size);
    const std::size_t count = std::min(size, quantised.size() - begin);
    const auto part = std::span(quantised).subspan(begin, count);
    segments[s] = {version, hashes[s], static_cast<std::uint32_t>(count),
                   compress_points(std::vector<Quantised>(part.begin(), part.end()), context.get())};
  }
  return first;
}

std::string append_segments(TileKey key, std::size_t first_point, std::span<const MapPoint> tail,
                            const TileParams& params, std::int32_t version, std::vector<TileSegment>& segments,
                            std::size_t& first) {
  if (std::string problem = tile_params_problem(params); !problem.empty()) return problem;
  std::size_t held = 0;
  for (const TileSegment& s : segments) held += s.n_points;
  if (first_point > held) return fmt::format("the update starts at point {} of a tile holding {}", first_point, held);
  if (first_point + tail.size() < held)
    return fmt::format("the update would shrink the tile from {} to {} points", held, first_point + tail.size());
  if (first_point + tail.size() > kMaxTilePoints) return "too many points for one tile";
  if (tail.empty() && first_point == held) {  // nothing new
    first = segments.size();
    return {};
  }
  const std::size_t size = params.segment_points;
  const std::size_t s = first_point / size;
  std::vector<MapPoint> part;
  part.reserve(first_point - s * size + tail.size());
  if (const std::size_t head = first_point - s * size; head > 0) {
    const TileSegment& segment = segments[s];  // exists: first_point <= held, and not on a boundary
    if (segment.frame.empty()) return fmt::format("segment {} of the tile is not in RAM", s);
    if (std::string problem = decode_segment(segment.frame, key, params.tile_size_m, params.quantum_m,
                                             params.centred, part);
        !problem.empty())
      return fmt::format("segment {} of the tile: {}", s, problem);
    if (part.size() < head) return fmt::format("segment {} of the tile holds {} points, not {}", s, part.size(), head);
    part.resize(head);  // decoded points lie on the quantum grid: they quantise to the same values
  }
  part.insert(part.end(), tail.begin(), tail.end());
  std::vector<TileSegment> rest(std::make_move_iterator(segments.begin() + static_cast<std::ptrdiff_t>(s)),
                                std::make_move_iterator(segments.end()));
  first = s + update_segments(key, part, params, version, rest);
  segments.resize(s);
  segments.insert(segments.end(), std::make_move_iterator(rest.begin()), std::make_move_iterator(rest.end()));
  return {};
}

std::size_t first_segment_after(std::span<const TileSegment> segments, std::int32_t held_version) {
  for (std::size_t s = 0; s < segments.size(); ++s)
    if (segments[s].version > held_version) return s;
  return segments.size();
}

std::string decode_segment(std::span<const std::uint8_t> frame, TileKey key, double tile_size_m, double quantum_m,
                           bool centred, std::vector<MapPoint>& out) {
  TileParams params;
  params.tile_size_m = tile_size_m;
  params.quantum_m = quantum_m;
  params.centred = centred;
  if (const std::string problem = tile_params_problem(params); !problem.empty()) return problem;
  const unsigned long long content = ZSTD_getFrameContentSize(frame.data(), frame.size());
  if (content == ZSTD_CONTENTSIZE_UNKNOWN || content == ZSTD_CONTENTSIZE_ERROR) return "not a zstd frame of known size";
  if (content % kBytesPerQuantisedPoint != 0 || content > kMaxSegmentPoints * kBytesPerQuantisedPoint)
    return fmt::format("segment of {} bytes is not whole points of at most {}", content, kMaxSegmentPoints);
  return decompress_points(frame, content / kBytesPerQuantisedPoint, key, params, out);
}

std::vector<std::uint8_t> pack_tile(const TileParams& params, std::span<const TileSegment> segments) {
  std::size_t n_points = 0;
  std::size_t bytes = kTileHeaderBytesFormat2 + 4 * segments.size();
  for (const TileSegment& s : segments) {
    n_points += s.n_points;
    bytes += s.frame.size();
  }
  std::vector<std::uint8_t> blob(bytes);
  std::memcpy(blob.data(), "ADT1", 4);
  put<std::uint16_t>(blob, 4, params.centred ? kTileFormat : std::uint16_t{2});
  put<std::uint16_t>(blob, 6, 0);
  put<std::uint32_t>(blob, 8, static_cast<std::uint32_t>(n_points));
  put<float>(blob, 12, static_cast<float>(params.tile_size_m));
  put<float>(blob, 16, static_cast<float>(params.quantum_m));
  put<std::uint32_t>(blob, 20, params.segment_points);
  put<std::uint32_t>(blob, 24, static_cast<std::uint32_t>(segments.size()));
  std::size_t at = kTileHeaderBytesFormat2;
  for (const TileSegment& s : segments) {
    put<std::uint32_t>(blob, at, static_cast<std::uint32_t>(s.frame.size()));
    at += 4;
  }
  for (const TileSegment& s : segments) {
    std::memcpy(blob.data() + at, s.frame.data(), s.frame.size());
    at += s.frame.size();
  }
  return blob;
}

std::vector<std::uint8_t> encode_tile(TileKey key, std::span<const MapPoint> points, const TileParams& params) {
  std::vector<TileSegment> segments;
  update_segments(key, points, params, 1, segments);
  return pack_tile(params, segments);
}

std::vector<std::uint8_t> encode_tile_format1(TileKey key, std::span<const MapPoint> points, const TileParams& params) {
  if (const std::string problem = tile_params_problem(params); !problem.empty()) throw std::invalid_argument(problem);
  if (points.size() > kMaxTilePoints) throw std::invalid_argument("too many points for one tile");
  TileParams corner = params;  // format 1 knew only the corner origin
  corner.centred = false;
  const CompressionContext context = make_context(params);
  const std::vector<std::uint8_t> frame = compress_points(quantise_tile(key, points, corner), context.get());
  std::vector<std::uint8_t> blob(kTileHeaderBytes + frame.size());
  std::memcpy(blob.data(), "ADT1", 4);
  put<std::uint16_t>(blob, 4, 1);
  put<std::uint16_t>(blob, 6, 0);
  put<std::uint32_t>(blob, 8, static_cast<std::uint32_t>(points.size()));
  put<float>(blob, 12, static_cast<float>(params.tile_size_m));
  put<float>(blob, 16, static_cast<float>(params.quantum_m));
  std::memcpy(blob.data() + kTileHeaderBytes, frame.data(), frame.size());
  return blob;
}

std::string unpack_tile(std::span<const std::uint8_t> blob, TileKey key, TileParams& params,
                        std::vector<TileSegment>& segments) {
  segments.clear();
  std::uint16_t format = 0;
  std::uint32_t n = 0;
  TileParams read = params;
  if (std::string problem = read_header(blob, format, n, read); !problem.empty()) return problem;
  if (format == 1) {  // one frame of every point: decode, then cut into segments
    std::vector<MapPoint> points;
    if (std::string problem = decompress_points(blob.subspan(kTileHeaderBytes), n, key, read, points);
        !problem.empty())
      return "tile: " + problem;
    read.segment_points = params.segment_points;
    if (std::string problem = tile_params_problem(read); !problem.empty()) return problem;
    // Exact: the points decoded lie on read's quantum grid.
    update_segments(key, points, read, 1, segments);
    params = read;
    return {};
  }
  const std::uint32_t n_segments = get<std::uint32_t>(blob, 24);
  if (n_segments != segment_count(n, read.segment_points))
    return fmt::format("tile of {} points in segments of {} claims {} segments", n, read.segment_points, n_segments);
  if (blob.size() < kTileHeaderBytesFormat2 + 4 * std::size_t{n_segments}) return "tile's segment table is cut short";
  std::size_t at = kTileHeaderBytesFormat2 + 4 * std::size_t{n_segments};
  std::vector<TileSegment> out(n_segments);
  for (std::uint32_t s = 0; s < n_segments; ++s) {
    const std::size_t size = get<std::uint32_t>(blob, kTileHeaderBytesFormat2 + 4 * std::size_t{s});
    if (size > blob.size() - at) return fmt::format("tile's segment {} runs past its end", s);
    const std::size_t begin = std::size_t{s} * read.segment_points;
    out[s].version = 1;
    out[s].n_points = static_cast<std::uint32_t>(std::min<std::size_t>(read.segment_points, n - std::min<std::size_t>(n, begin)));
    out[s].frame.assign(blob.begin() + static_cast<std::ptrdiff_t>(at), blob.begin() + static_cast<std::ptrdiff_t>(at + size));
    const unsigned long long content = ZSTD_getFrameContentSize(out[s].frame.data(), out[s].frame.size());
    if (content != std::size_t{out[s].n_points} * kBytesPerQuantisedPoint)
      return fmt::format("tile's segment {}: zstd frame size does not match its point count", s);
    at += size;
  }
  if (at != blob.size()) return "tile has bytes after its last segment";
  segments = std::move(out);
  params = read;
  return {};
}

std::string decode_tile(std::span<const std::uint8_t> blob, TileKey key, std::vector<MapPoint>& out) {
  out.clear();
  std::uint16_t format = 0;
  std::uint32_t n = 0;
  TileParams params;
  if (std::string problem = read_header(blob, format, n, params); !problem.empty()) return problem;
  if (format == 1) {
    std::string problem = decompress_points(blob.subspan(kTileHeaderBytes), n, key, params, out);
    if (!problem.empty()) out.clear();
    return problem.empty() ? problem : "tile's " + problem;
  }
  std::vector<TileSegment> segments;
  if (std::string problem = unpack_tile(blob, key, params, segments); !problem.empty()) return problem;
  out.reserve(n);
  for (std::size_t s = 0; s < segments.size(); ++s) {
    if (std::string problem = decompress_points(segments[s].frame, segments[s].n_points, key, params, out);
        !problem.empty()) {
      out.clear();
      return fmt::format("tile's segment {}: {}", s, problem);
    }
  }
  return {};
}

}  // namespace adit::protocol
