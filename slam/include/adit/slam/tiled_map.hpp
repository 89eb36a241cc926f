#pragma once
// The global map of a session: registered scans accumulated in fixed-size
// cubic tiles (default 20 m), each a voxel grid (default 5 cm) that keeps the
// first point to land in each voxel. Keeping a measured point rather than a
// centroid is KISS-ICP's rule (Vizzo et al. 2023, §III-B): nothing is
// invented, and a surveyor's point is one the sensor saw. Tiles record
// whether they changed, so a publisher sends only what is new.
//
// Coordinates: tile (i, j, k) covers [i·s, (i+1)·s) × … in the map frame, the
// same convention as protocol::tile_of. Inside a tile the voxel grid starts at
// the tile's corner, so no voxel straddles two tiles.

#include <compare>
#include <cstdint>
#include <map>
#include <set>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace adit::slam {

struct TileCoord {
  std::int32_t x = 0;
  std::int32_t y = 0;
  std::int32_t z = 0;
  auto operator<=>(const TileCoord&) const = default;
};

struct MapSample {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();  // map frame, m
  float intensity = 0.0F;
  double time_s = 0.0;  // when the sensor measured it (the scan's stamp)
};

struct TiledMapConfig {
  float tile_size_m = 20.0F;
  float voxel_m = 0.05F;
  std::uint8_t min_hits = 2;  // hits before a voxel's first point enters the map (1 = at once)
};

// "" when usable, else why not: positive sizes, at most 1600 voxels per tile
// edge (so a voxel's index inside its tile fits 32 bits).
std::string tiled_map_config_problem(const TiledMapConfig& config);

class TiledVoxelMap {
 public:
  // `config` must be usable (see tiled_map_config_problem); throws std::invalid_argument otherwise.
  explicit TiledVoxelMap(const TiledMapConfig& config);

  // Adds points given in the map frame (intensities: one per point or empty);
  // returns how many voxels this confirmed (entered the map). Non-finite points are skipped.
  std::size_t add(std::span<const Eigen::Vector3f> points, std::span<const float> intensities, double time_s);

  // The tiles that gained points since the previous call, in coordinate order.
  std::vector<TileCoord> take_changed();

  // The map points of one tile, confirmed voxels only (empty when the tile does not exist).
  std::span<const MapSample> tile(const TileCoord& coord) const;
  std::vector<TileCoord> tile_coords() const;
  std::size_t size() const { return size_; }               // map points (confirmed voxels)
  std::size_t candidates() const { return candidates_; }   // voxels hit at least once
  std::size_t tile_count() const { return tiles_.size(); }
  const TiledMapConfig& config() const { return config_; }

  TileCoord tile_of(const Eigen::Vector3f& p) const;

 private:
  // The voxels a tile holds: an open-addressing hash set of 32-bit voxel
  // indices (linear probing, Knuth's multiplicative hash, load ≤ 1/2), about
  // 8 bytes per point against ~40 for std::unordered_set's nodes.
  // The voxels a tile has seen: an open-addressing hash map from the 32-bit
  // voxel index to the voxel's candidate (linear probing, Knuth's
  // multiplicative hash, load ≤ 1/2): 16 bytes per slot.
  class VoxelIndex {
   public:
    // The candidate of `voxel`, or `next` (then stored) when it is new.
    std::uint32_t find_or_insert(std::uint32_t voxel, std::uint32_t next);
   private:
    static constexpr std::uint32_t kEmpty = 0xFFFFFFFFU;  // > any index (≤ 1600³ - 1)
    struct Slot {
      std::uint32_t voxel = kEmpty;
      std::uint32_t candidate = 0;
    };
    void grow();
    std::vector<Slot> slots_;
    std::size_t size_ = 0;
  };
  struct Tile {
    VoxelIndex voxels;
    std::vector<MapSample> candidates;  // first point of each voxel hit so far
    std::vector<std::uint8_t> hits;     // per candidate, saturating
    std::vector<MapSample> points;      // confirmed: what the map holds
  };
  TiledMapConfig config_;
  std::int32_t voxels_per_edge_;
  std::map<TileCoord, Tile> tiles_;
  std::set<TileCoord> changed_;
  std::size_t size_ = 0;
  std::size_t candidates_ = 0;
};

}  // namespace adit::slam
