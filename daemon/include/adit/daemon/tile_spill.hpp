#pragma once
// The session folder's tiles/<id>.adt files (protocol/tile_codec.hpp) as the
// mapping thread's store for tiles it evicted from RAM (slam::TiledVoxelMap::evict),
// and as the finished session's tiles. The codec keeps positions (1 mm) and
// intensities, not each point's time: a tile read back gives its points the
// time of the newest point it held when written (kept here, a few bytes per tile).

#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "adit/protocol/map_point.hpp"
#include "adit/protocol/tile_codec.hpp"
#include "adit/slam/tiled_map.hpp"

namespace adit::daemon {

std::vector<protocol::MapPoint> map_points_of(std::span<const slam::MapSample> samples);

// The codec parameters of stored tiles/<id>.adt: they change rarely (evicted)
// or never again (a finished session), so they take the largest segments,
// which compress best (a 112 000-point tunnel tile: 176 kB against 229 kB in
// the stream's 1024-point segments; bench_tile_stream).
protocol::TileParams stored_tile_params(double tile_size_m);

class TileSpill {
 public:
  TileSpill(std::filesystem::path dir, protocol::TileParams params) : dir_(std::move(dir)), params_(params) {}

  // Encodes the tile and writes it (whole, then renamed into place, so a
  // reader never sees half a file); "" or why not.
  std::string write(const slam::TileCoord& coord, std::span<const slam::MapSample> points);
  // Reads a tile written before into `out` (replaced); "" or why not.
  std::string read(const slam::TileCoord& coord, std::vector<slam::MapSample>& out) const;
  // The whole content of a tile of `map` into `out`: its stored part (read
  // back) and what the map holds (tile()), or the stored file alone when the
  // tile is evicted; "" or why not.
  std::string whole_tile(const slam::TiledVoxelMap& map, const slam::TileCoord& coord,
                         std::vector<slam::MapSample>& out) const;
  std::filesystem::path file_of(const slam::TileCoord& coord) const;
  const std::filesystem::path& dir() const { return dir_; }

 private:
  // read() leaving room for `extra` more points in `out`.
  std::string read_into(const slam::TileCoord& coord, std::vector<slam::MapSample>& out, std::size_t extra) const;

  std::filesystem::path dir_;
  protocol::TileParams params_;
  std::map<slam::TileCoord, double> newest_time_s_;
};

}  // namespace adit::daemon
