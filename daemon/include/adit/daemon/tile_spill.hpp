#pragma once
// The session folder's tiles/<id>.adt files (protocol/tile_codec.hpp) as the
// mapping thread's store for tiles it evicted from RAM (slam::TiledVoxelMap::evict),
// and as the finished session's tiles. The codec keeps positions (1 mm) and
// intensities, not each point's time, and sorts each segment's points (a
// segment: the next segment_points of the tile in append order). So the time
// kept here is one per segment, its points' median (8 bytes per 4096 points):
// a tile read back gives each point the time of the scans around the one
// that mapped it, which the loop closure's correction through time needs to
// move it (slam/correction_track.hpp), rather than one time for the whole
// tile. A tile this object did not write (another run's) reads back with time 0.

#include <cstdint>
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
  std::map<slam::TileCoord, std::vector<double>> segment_times_s_;  // each segment's median time
};

}  // namespace adit::daemon
