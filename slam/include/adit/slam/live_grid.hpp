#pragma once
// The 2D occupancy grid kept while mapping, for the tablet and for a robot's
// planner: a horizontal slice of the world at the sensor's height, as a 2D
// laser scanner there would see it.
//
// Each scan (map frame) is cut to a band below and above the sensor, as
// ROS's pointcloud_to_laserscan does: a point in the band is an obstacle in
// its cell; per bearing, the nearest one ends a free ray from the sensor. A
// point above or below the band says the band was free up to where its ray
// left it. Cells hold log-odds (Thrun, Burgard, Fox, Probabilistic Robotics,
// §9.2, eq. 9.7), updated once per scan per cell with OctoMap's hit / miss
// probabilities 0.7 / 0.4 and clamping 0.12 / 0.97 (Hornung et al. 2013, §3);
// a cell hit and passed in one scan counts as hit (OctoMap does the same), and
// a pass through a cell that reads occupied counts half (rays graze walls).
// Far away a small attitude error moves the floor and ceiling into the band,
// so the band narrows with range by a tilt tolerance.
// The value a cell reads as is ROS map_saver's: occupied at P >= 0.65, free
// at P <= 0.196, else unknown (nav_msgs/OccupancyGrid's 100, 0, -1).
//
// The grid is cut into square patches that exist once touched; a patch whose
// read values changed is reported by take_changed() with a new version, so
// only those go to the tablet. A patch that no ray can reach any more (beyond
// max_range and a patch's width from the sensor) is frozen: its log-odds
// compressed (zstd), its scan stamps dropped, 64 kB down to a few; it thaws,
// exactly as it was, when a ray reaches it again. Not thread-safe; allocates
// when the grid grows or a patch freezes or thaws (a patch at a time), not
// per point.

#include <compare>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

namespace adit::slam {

struct LiveGridConfig {
  float resolution_m = 0.05F;
  float band_below_m = 0.5F;   // the slice: from this far below the sensor ...
  float band_above_m = 0.5F;   // ... to this far above it
  // The band narrows by r·tan(this) at horizontal range r from both sides: an
  // attitude error this large lifts the floor at r into the band (or lowers
  // the ceiling); points in that margin are neither obstacle nor free.
  float tilt_tolerance_deg = 1.0F;
  float max_range_m = 40.0F;   // horizontal; farther points are left out
  int bearings = 1440;         // free rays per scan: the nearest obstacle per 0.25° (0.16-0.32°)
  int patch_cells = 128;       // a patch is patch_cells × patch_cells cells
  bool freeze_far_patches = true;  // compress patches no ray can reach (false: all stay as they are)
};

// Patch (x, y) holds cells [x·n, (x+1)·n) × [y·n, (y+1)·n), n = patch_cells;
// cell (i, j) spans [i, i+1)·resolution in x (same in y) of the map frame.
struct GridPatchCoord {
  std::int32_t x = 0, y = 0;
  auto operator<=>(const GridPatchCoord&) const = default;
};

inline constexpr std::int8_t kGridUnknown = -1;
inline constexpr std::int8_t kGridFree = 0;
inline constexpr std::int8_t kGridOccupied = 100;

struct LiveGridCounts {
  std::uint64_t scans = 0;
  std::uint64_t hit_updates = 0;   // cells updated as hit (one per cell per scan)
  std::uint64_t miss_updates = 0;  // cells updated as passed
  std::uint64_t freezes = 0;       // patches compressed as the sensor left them
  std::uint64_t thaws = 0;         // frozen patches a ray reached again
};

class LiveGrid {
 public:
  explicit LiveGrid(const LiveGridConfig& config);

  // One scan: `origin` the sensor's position and `points` the scan, both in
  // the map frame. Non-finite points are skipped.
  void insert(const Eigen::Vector3f& origin, std::span<const Eigen::Vector3f> points);

  // The patches whose read values changed since the last call, each with its
  // version raised by one; in (x, y) order.
  std::vector<GridPatchCoord> take_changed();
  // Every patch that exists, in (x, y) order.
  std::vector<GridPatchCoord> patch_coords() const;
  // A patch's values (kGridUnknown, kGridFree, kGridOccupied), row-major,
  // row 0 at the lowest y; `out` holds patch_cells² values. A patch that does
  // not exist reads unknown.
  void read(GridPatchCoord patch, std::span<std::int8_t> out) const;
  // The version of a patch: 0 before its first reported change.
  std::int32_t version(GridPatchCoord patch) const;

  const LiveGridConfig& config() const { return config_; }
  std::size_t patch_count() const { return patches_.size(); }
  std::size_t frozen_count() const { return frozen_; }
  std::size_t memory_bytes() const;
  const LiveGridCounts& counts() const { return counts_; }

 private:
  struct Patch {
    std::vector<std::int16_t> log_odds;  // ×1000; empty while frozen
    std::vector<std::uint16_t> stamp;    // the last scan that updated the cell (wraps); empty while frozen
    std::vector<std::uint8_t> frozen;    // the log-odds, zstd-compressed, while frozen
    std::int32_t version = 0;
    bool changed = false;
  };
  struct Ray {
    float hit_range = 0.0F;   // nearest obstacle in the band, 0 = none
    float free_range = 0.0F;  // farthest the band was seen free, without an obstacle
    Eigen::Vector2f hit_dir = Eigen::Vector2f::Zero();
    Eigen::Vector2f free_dir = Eigen::Vector2f::Zero();
  };
  static std::int64_t key(GridPatchCoord c) {
    return (static_cast<std::int64_t>(c.x) << 32) ^ static_cast<std::uint32_t>(c.y);
  }
  static GridPatchCoord coord_of(std::int64_t key) {
    return {static_cast<std::int32_t>(key >> 32), static_cast<std::int32_t>(static_cast<std::uint32_t>(key))};
  }
  Patch& patch_at(GridPatchCoord c);
  void freeze(Patch& p);
  void thaw_into(const std::vector<std::uint8_t>& frozen, std::vector<std::int16_t>& log_odds) const;
  // Freezes the patches beyond every ray from `origin` (map xy).
  void freeze_far(const Eigen::Vector2f& origin);
  // Updates a cell of `p` once this scan; false when it was updated already.
  bool update(Patch& p, std::size_t cell, std::int16_t delta);
  static float pseudo_angle(float x, float y);
  void trace_free(const Eigen::Vector2f& from, const Eigen::Vector2f& to);

  LiveGridConfig config_;
  float inv_resolution_;
  float tilt_tan_;
  std::unordered_map<std::int64_t, Patch> patches_;
  std::vector<Ray> rays_;  // one per bearing, reused each scan
  std::uint16_t scan_stamp_ = 0;
  std::size_t frozen_ = 0;
  // The patch of the last update, so a ray's cells find theirs without a lookup.
  Patch* last_patch_ = nullptr;
  GridPatchCoord last_coord_{};
  LiveGridCounts counts_;
};

}  // namespace adit::slam
