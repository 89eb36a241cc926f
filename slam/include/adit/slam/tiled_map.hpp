#pragma once
// The global map of a session: registered scans accumulated in fixed-size
// cubic tiles (default 20 m), each a voxel grid (default 5 cm) that keeps the
// first point to land in each voxel. Keeping a measured point rather than a
// centroid is KISS-ICP's rule (Vizzo et al. 2023, §III-B): nothing is
// invented, and a surveyor's point is one the sensor saw. Tiles record
// whether they changed, so a publisher sends only what is new.
//
// A long session's map outgrows RAM, so tiles the sensor has left can be
// evicted: evict() hands out a tile's confirmed points and forgets the tile
// (its unconfirmed candidates, voxels hit fewer than min_hits times, are lost);
// the caller stores them. When the sensor comes back, restore() marks the
// stored points' voxels as taken, so the tile is continued, not duplicated,
// but keeps neither the points nor a candidate per voxel: a bit per voxel in
// 8×8×8 blocks (64 bytes per block a surface crosses, about a byte per surface
// voxel against ~70 for a voxel hit in RAM), so a tile revisited again and
// again costs RAM only for what is new since its last restore. Such a tile's
// whole content is then the caller's stored part plus tile(). TileEviction
// says which tiles are cold. No file I/O here: slam/ is pure.
//
// Coordinates: tile (i, j, k) covers [i·s, (i+1)·s) × … in the map frame, the
// same convention as protocol::tile_of. Inside a tile the voxel grid starts at
// the tile's corner, so no voxel straddles two tiles.

#include <array>
#include <compare>
#include <cstdint>
#include <map>
#include <string>
#include <set>
#include <span>
#include <utility>
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

  // The tiles that gained points since the previous call, in coordinate order
  // (evicted tiles are not among them: evict() says whether one had changed).
  std::vector<TileCoord> take_changed();

  // The map points of one resident tile that the map holds itself: confirmed
  // since the tile was made or restored (empty when it does not exist or is
  // evicted). A restored tile's earlier points are the caller's (stored_points).
  std::span<const MapSample> tile(const TileCoord& coord) const;
  // How many points of a resident tile the caller holds (given to restore()), 0 if none.
  std::size_t stored_points(const TileCoord& coord) const;
  std::vector<TileCoord> tile_coords() const;          // resident tiles, in coordinate order
  std::vector<TileCoord> evicted_coords() const;       // evicted tiles, in coordinate order
  std::size_t evicted_points(const TileCoord& coord) const;  // points an evicted tile held (0 if not evicted)
  bool is_evicted(const TileCoord& coord) const { return evicted_.contains(coord); }
  // Voxels a resident tile holds as candidates (confirmed or not), 0 if none.
  std::size_t held_voxels(const TileCoord& coord) const;
  std::size_t size() const { return size_; }               // map points (confirmed voxels), evicted tiles included
  std::size_t candidates() const { return candidates_; }   // voxels hit at least once, in resident tiles
  std::size_t tile_count() const { return tiles_.size() + evicted_.size(); }
  std::size_t resident_tile_count() const { return tiles_.size(); }
  std::size_t resident_points() const { return size_ - evicted_size_ - stored_size_; }  // points held in RAM
  std::size_t lost_candidates() const { return lost_candidates_; }  // unconfirmed voxels dropped by evict()
  std::size_t dropped_in_evicted() const { return dropped_in_evicted_; }  // add(): points in an evicted tile
  // Bytes held by the resident tiles' vectors and indices (capacities, not sizes).
  std::size_t memory_bytes() const;
  // Bytes a compaction of one resident tile (evict, then restore) would free:
  // its candidates, hits, points and voxel index; its stored voxels' bits stay.
  // 0 when it is not resident.
  std::size_t compactable_bytes(const TileCoord& coord) const;

  // A resident tile leaves RAM: returns its confirmed points and whether it had
  // changed since the last take_changed() (then the caller still owes it to
  // whoever publishes tiles). Voxels below min_hits are lost. Points later
  // added into an evicted tile are skipped and counted (dropped_in_evicted):
  // restore() it first. Empty and false when `coord` is not resident.
  struct Evicted {
    std::vector<MapSample> points;
    bool changed = false;
  };
  Evicted evict(const TileCoord& coord);
  // An evicted tile comes back: `points` are what the caller stored for it
  // (evict()'s points, merged with any earlier stored part; or a decoded copy).
  // Their voxels count as confirmed, so new points in them are not added
  // again; the points themselves stay the caller's (stored_points()), and
  // evict() later hands out only what is new. A no-op when `coord` is resident.
  void restore(const TileCoord& coord, std::span<const MapSample> points);
  // The evicted tiles that any of `points` falls into, in coordinate order:
  // what must be restored before add() takes them.
  std::vector<TileCoord> evicted_hit_by(std::span<const Eigen::Vector3f> points) const;
  // Per point, 1 when its voxel, or one within `reach_voxels` of it along
  // each axis, is in the map (confirmed, or stored by a restore()), else 0
  // (also for non-finite points and tiles not resident: restore those first).
  // `held` gets one entry per point.
  void holds(std::span<const Eigen::Vector3f> points, std::vector<std::uint8_t>& held, int reach_voxels = 0) const;
  const TiledMapConfig& config() const { return config_; }

  TileCoord tile_of(const Eigen::Vector3f& p) const;

 private:
  // The voxels a tile has seen: an open-addressing hash map from the 32-bit
  // voxel index to the voxel's candidate (linear probing, Knuth's
  // multiplicative hash, load ≤ 1/2): 16 bytes per slot.
  class VoxelIndex {
   public:
    // The candidate of `voxel`, or `next` (then stored) when it is new.
    std::uint32_t find_or_insert(std::uint32_t voxel, std::uint32_t next);
    // The candidate of `voxel`, or kEmpty.
    std::uint32_t find(std::uint32_t voxel) const;
    std::size_t memory_bytes() const { return slots_.capacity() * sizeof(Slot); }
    static constexpr std::uint32_t kEmpty = 0xFFFFFFFFU;  // > any index (≤ 1600³ - 1)
   private:
    struct Slot {
      std::uint32_t voxel = kEmpty;
      std::uint32_t candidate = 0;
    };
    void grow();
    std::vector<Slot> slots_;
    std::size_t size_ = 0;
  };
  // A set of voxels as one bit per voxel in 8×8×8 blocks: a block index
  // (VoxelIndex: block → bitmap) and 512-bit bitmaps.
  class VoxelBits {
   public:
    void insert(std::uint32_t block, std::uint32_t bit);
    bool contains(std::uint32_t block, std::uint32_t bit) const;
    bool empty() const { return bitmaps_.empty(); }
    std::size_t memory_bytes() const { return blocks_.memory_bytes() + bitmaps_.capacity() * sizeof(Bitmap); }
   private:
    using Bitmap = std::array<std::uint64_t, 8>;
    VoxelIndex blocks_;
    std::vector<Bitmap> bitmaps_;
  };
  struct Tile {
    VoxelIndex voxels;
    std::vector<MapSample> candidates;  // first point of each voxel hit so far
    std::vector<std::uint8_t> hits;     // per candidate, saturating
    std::vector<MapSample> points;      // confirmed since made or restored: what the map holds
    VoxelBits stored;                   // voxels of the points the caller holds (restore())
    std::size_t stored_points = 0;
  };
  // (block, bit) of a voxel index for VoxelBits.
  std::pair<std::uint32_t, std::uint32_t> block_of(std::uint32_t voxel) const;
  Tile& new_tile(const TileCoord& coord);
  static std::size_t compactable_bytes(const Tile& tile);
  std::uint32_t voxel_of(const Eigen::Vector3f& p, const Eigen::Vector3f& origin) const;
  Eigen::Vector3f origin_of(const TileCoord& coord) const;

  TiledMapConfig config_;
  std::int32_t voxels_per_edge_;
  std::map<TileCoord, Tile> tiles_;
  std::map<TileCoord, std::size_t> evicted_;  // evicted tile → its point count
  std::set<TileCoord> changed_;
  std::size_t size_ = 0;
  std::size_t evicted_size_ = 0;
  std::size_t stored_size_ = 0;  // points of resident tiles that the caller holds
  std::size_t candidates_ = 0;
  std::size_t lost_candidates_ = 0;
  std::size_t dropped_in_evicted_ = 0;
};

// Which resident tiles the sensor has left. A tile is cold once its whole cube
// has lain farther than `radius_m` from the sensor at `after_keyframes`
// consecutive keyframes. With radius_m ≥ map.max_range_m (plus the distance a
// deskewed point can move, a few cm) no point of a scan taken there can fall
// into the tile; the keyframe count adds hysteresis, so a path along a tile
// boundary does not evict and reload the same tile over and over.
//
// A tile the sensor never leaves (it works around it for an hour) or keeps
// coming back to would still grow in RAM: a tile holding more than
// `compact_voxels` voxels is crowded, and the caller evicts and restores it at
// once, so its points go to the store and only a bit per voxel stays.
//
// The tiles around the sensor grow too, each by less: lap after lap of a
// route adds what the drifting odometry puts beside the earlier laps. With a
// budget of `resident_bytes`, when the resident tiles hold more, the tiles
// that would free most are crowded as well, until what stays is within three
// quarters of the budget (the quarter is room to grow before the next round,
// so compactions come in rounds, not at every keyframe).
struct TileEvictionConfig {
  float radius_m = 50.0F;
  int after_keyframes = 20;        // ≤ 0: never evict
  std::size_t compact_voxels = 0;  // 0: never compact
  std::size_t resident_bytes = 0;  // 0: no budget
};

class TileEviction {
 public:
  explicit TileEviction(const TileEvictionConfig& config) : config_(config) {}
  // Once per keyframe: the resident tiles that are cold now, in coordinate order.
  std::vector<TileCoord> cold_tiles(const TiledVoxelMap& map, const Eigen::Vector3f& sensor);
  // The resident tiles to compact, in coordinate order: those holding more
  // than compact_voxels voxels, and while the map is over its budget, the
  // largest (by compactable_bytes) down to three quarters of it.
  std::vector<TileCoord> crowded_tiles(const TiledVoxelMap& map) const;

 private:
  TileEvictionConfig config_;
  std::map<TileCoord, int> far_for_;  // resident tile → consecutive keyframes beyond the radius
};

// Distance from `p` to the cube of tile `coord` (0 inside).
float distance_to_tile(const TileCoord& coord, float tile_size_m, const Eigen::Vector3f& p);

}  // namespace adit::slam
