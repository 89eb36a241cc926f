#include "adit/daemon/tile_spill.hpp"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <system_error>

#include <fmt/format.h>

namespace adit::daemon {

protocol::TileParams stored_tile_params(double tile_size_m) {
  protocol::TileParams p;
  p.tile_size_m = tile_size_m;
  p.segment_points = protocol::kMaxSegmentPoints;
  return p;
}

std::vector<protocol::MapPoint> map_points_of(std::span<const slam::MapSample> samples) {
  std::vector<protocol::MapPoint> out;
  out.reserve(samples.size());
  for (const slam::MapSample& s : samples)
    out.push_back({s.position.x(), s.position.y(), s.position.z(), s.intensity, s.time_s});
  return out;
}

std::filesystem::path TileSpill::file_of(const slam::TileCoord& coord) const {
  return dir_ / fmt::format("{}.adt", protocol::tile_id({coord.x, coord.y, coord.z}));
}

// The tile is encoded one segment at a time (protocol::append_segments at
// each segment's start): a tile of ~1 M points held as protocol::MapPoint
// for encode_tile was 40 MB in flight at each compaction (decision 074).
std::string TileSpill::write(const slam::TileCoord& coord, std::span<const slam::MapSample> points) {
  const protocol::TileKey key{coord.x, coord.y, coord.z};
  std::vector<std::uint8_t> blob;
  if (points.empty()) {
    blob = protocol::encode_tile(key, {}, params_);
  } else {
    std::vector<protocol::TileSegment> segments;
    std::vector<protocol::MapPoint> chunk;
    for (std::size_t begin = 0; begin < points.size(); begin += params_.segment_points) {
      chunk = map_points_of(points.subspan(begin, std::min<std::size_t>(params_.segment_points, points.size() - begin)));
      std::size_t first = 0;
      if (std::string problem = protocol::append_segments(key, begin, chunk, params_, 1, segments, first);
          !problem.empty())
        return fmt::format("{}: cannot encode the tile: {}", file_of(coord).string(), problem);
    }
    blob = protocol::pack_tile(params_, segments);
  }
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (ec) return fmt::format("{}: cannot create the folder: {}", dir_.string(), ec.message());
  const std::filesystem::path file = file_of(coord);
  std::filesystem::path part = file;
  part += ".part";
  {
    std::ofstream out(part, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(blob.data()), static_cast<std::streamsize>(blob.size()));
    out.close();
    if (!out) return fmt::format("{}: cannot write the tile", part.string());
  }
  std::filesystem::rename(part, file, ec);
  if (ec) return fmt::format("{}: cannot rename the tile into place: {}", file.string(), ec.message());
  std::vector<double>& times = segment_times_s_[coord];
  times.clear();
  std::vector<double> segment;
  for (std::size_t begin = 0; begin < points.size(); begin += params_.segment_points) {
    const std::size_t end = std::min<std::size_t>(points.size(), begin + params_.segment_points);
    segment.clear();
    for (std::size_t i = begin; i < end; ++i) segment.push_back(points[i].time_s);
    const auto middle = segment.begin() + static_cast<std::ptrdiff_t>(segment.size() / 2);
    std::nth_element(segment.begin(), middle, segment.end());
    times.push_back(*middle);
  }
  times.shrink_to_fit();
  return "";
}

std::string TileSpill::read(const slam::TileCoord& coord, std::vector<slam::MapSample>& out) const {
  return read_into(coord, out, 0);
}

// A tile of ~1 M points is 24 MB as samples: it is decoded one segment at a
// time (≤ 4096 points), with `out` reserved once for the whole tile plus
// `extra`, rather than through a whole-tile vector of protocol::MapPoint
// (40 B a point) and a vector that grows by doubling.
std::string TileSpill::read_into(const slam::TileCoord& coord, std::vector<slam::MapSample>& out,
                                 std::size_t extra) const {
  out.clear();
  const std::filesystem::path file = file_of(coord);
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) return fmt::format("{}: cannot open the tile", file.string());
  const std::streamoff size = in.tellg();
  in.seekg(0);
  std::vector<std::uint8_t> blob(size > 0 ? static_cast<std::size_t>(size) : 0);
  in.read(reinterpret_cast<char*>(blob.data()), static_cast<std::streamsize>(blob.size()));
  if (size < 0 || !in) return fmt::format("{}: cannot read the tile", file.string());
  const protocol::TileKey key{coord.x, coord.y, coord.z};
  protocol::TileParams params = params_;
  std::vector<protocol::TileSegment> segments;
  if (std::string problem = protocol::unpack_tile(blob, key, params, segments); !problem.empty())
    return fmt::format("{}: {}", file.string(), problem);
  std::vector<std::uint8_t>().swap(blob);  // the segments hold copies of its frames
  std::size_t n = 0;
  for (const protocol::TileSegment& segment : segments) n += segment.n_points;
  const auto found = segment_times_s_.find(coord);
  const std::span<const double> times = found == segment_times_s_.end() ? std::span<const double>() : found->second;
  out.reserve(n + extra);
  std::vector<protocol::MapPoint> points;
  points.reserve(protocol::kMaxSegmentPoints);
  for (std::size_t s = 0; s < segments.size(); ++s) {
    points.clear();
    if (std::string problem = protocol::decode_segment(segments[s].frame, key, params.tile_size_m, params.quantum_m,
                                                                params.centred, points);
        !problem.empty()) {
      out.clear();
      return fmt::format("{}: tile's segment {}: {}", file.string(), s, problem);
    }
    std::vector<std::uint8_t>().swap(segments[s].frame);
    const double time_s = s < times.size() ? times[s] : 0.0;
    for (const protocol::MapPoint& p : points)
      out.push_back({Eigen::Vector3f(static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)),
                     p.intensity, time_s});
  }
  return "";
}

std::string TileSpill::whole_tile(const slam::TiledVoxelMap& map, const slam::TileCoord& coord,
                                  std::vector<slam::MapSample>& out) const {
  out.clear();
  const std::span<const slam::MapSample> held = map.tile(coord);
  if (map.is_evicted(coord) || map.stored_points(coord) > 0) {
    // Room for what the map holds too: inserting it would double the capacity.
    if (std::string problem = read_into(coord, out, held.size()); !problem.empty()) return problem;
  } else {
    out.reserve(held.size());
  }
  out.insert(out.end(), held.begin(), held.end());
  return "";
}

}  // namespace adit::daemon
