#pragma once
// The local map of the odometry: points kept in a hash of cubic voxels, at most
// kMaxPointsPerVoxel per voxel, bounded by distance from the sensor, as in
// KISS-ICP (Vizzo et al., RA-L 2023, §III-C). Unlike KISS-ICP's hash map it
// has a fixed capacity set at construction and never allocates afterwards, so
// the odometry thread can own it in steady state (open addressing, linear
// probing, backward-shift deletion: Knuth, TAOCP vol. 3, §6.4, Algorithm R).
//
// Point-to-plane registration asks for the plane through the k map points
// nearest a query (as LOAM / FAST-LIO do), not for a plane fitted inside one
// voxel: a VLP-16's sparse rings leave most single voxels with too few points
// to fit, and snapping to ring points (point-to-point) pulls every scan back
// towards the previous sensor position.

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "adit/slam/voxel_key.hpp"

namespace adit::slam {

struct MapNeighbor {
  Eigen::Vector3f point = Eigen::Vector3f::Zero();  // the nearest map point
  float distance_sq = 0.0F;
  bool found = false;
};

// A local plane of the map: a point on it (the neighbours' mean) and its unit normal.
struct MapPlane {
  Eigen::Vector3f point = Eigen::Vector3f::Zero();
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();
  bool found = false;
};

class VoxelHashMap {
 public:
  static constexpr int kMaxPointsPerVoxel = 20;
  static constexpr int kMaxPlaneNeighbors = 16;

  // capacity_voxels is rounded up to a power of two; the table is kept at
  // most 3/4 full (beyond that new voxels are refused and counted).
  // min_point_spacing_m > 0: a point closer than this to one already in its
  // voxel is refused (KISS-ICP ≥ 1.0 uses voxel_size / sqrt(max points)).
  // Without it a voxel keeps its first kMaxPointsPerVoxel points: the rings of
  // the few scans that first saw it, repeated, and nothing of later scans.
  //
  // The points' storage (capacity × kMaxPointsPerVoxel points: 31.5 MB at
  // 2^17) is written at construction (`touched`), so a caller on a hot path
  // (the odometry) takes no page fault later; `on_first_use` leaves it to
  // become resident a page at a time as voxels are first used, for a thread
  // that may allocate (the mapping thread's refiner): a mine drive uses about
  // half of it (docs/decisions/032-aditd-memory.md).
  enum class Storage : std::uint8_t { touched, on_first_use };
  VoxelHashMap(float voxel_size_m, std::size_t capacity_voxels, float min_point_spacing_m = 0.0F,
               Storage storage = Storage::touched);

  // Adds points (map frame). A point lands in its voxel unless the voxel is
  // full, or the table is, or (with a minimum spacing) a point of the voxel
  // lies closer than it; refused points are counted in dropped_points().
  void add(std::span<const Eigen::Vector3f> points);

  // Removes every voxel whose first point is farther than max_distance_m from origin.
  void remove_far(const Eigen::Vector3f& origin, float max_distance_m);

  // The nearest point among the 27 voxels around `query` closer than
  // max_distance_m (found == false when there is none).
  MapNeighbor nearest(const Eigen::Vector3f& query,
                      float max_distance_m = std::numeric_limits<float>::infinity()) const;

  // The plane through the `neighbors` (≤ kMaxPlaneNeighbors) map points
  // nearest `query`, all within one voxel edge of it (so the 27 voxels around
  // it hold them all). Found only when they span a plane: not a line (a
  // single ring of a spinning LiDAR), and every one within
  // max_plane_error_m of the plane.
  MapPlane nearest_plane(const Eigen::Vector3f& query, int neighbors, float max_plane_error_m = 0.1F) const;

  // A hint, no effect on results: starts loading the slots of the 27 voxels
  // around `query` into cache. The search is bound by cache misses on the
  // table (measured on 64-beam scans), so callers issue this a few queries ahead.
  void prefetch_around(const Eigen::Vector3f& query) const;

  void clear();
  bool empty() const { return voxel_count_ == 0; }
  std::size_t voxel_count() const { return voxel_count_; }
  std::size_t point_count() const;
  std::uint64_t dropped_points() const { return dropped_points_; }
  float voxel_size() const { return voxel_size_; }
  float min_point_spacing() const { return min_point_spacing_; }
  std::size_t capacity() const { return slots_.size(); }

  template <typename F>
  void for_each_point(F&& f) const {
    for (std::size_t s = 0; s < slots_.size(); ++s)
      for (int i = 0; i < slots_[s].count; ++i) f(voxels_[s].points[static_cast<std::size_t>(i)]);
  }

  VoxelKey key_of(const Eigen::Vector3f& p) const { return voxel_key(p, inverse_voxel_size_); }

 private:
  // Probing touches only the compact slots (4 per cache line); a voxel's
  // points and plane, at the same index, are read only on a hit.
  struct Slot {
    VoxelKey key;
    std::int32_t count = 0;  // 0 = empty slot
  };
  struct Voxel {
    std::array<Eigen::Vector3f, kMaxPointsPerVoxel> points;
  };

  std::size_t home_of(const VoxelKey& key) const;
  std::size_t index_of(const VoxelKey& key) const;  // its slot, or the empty slot ending its probe run
  // The slot index holding `key`, or kNone.
  std::size_t find(const VoxelKey& key) const;
  std::size_t find_or_insert(const VoxelKey& key);
  void erase_at(std::size_t index);
  // Visits the 27 voxels around `query`, own voxel first, skipping those whose
  // box is farther than bound() (re-read after each voxel): f(points, count).
  template <typename Bound, typename F>
  void visit_around(const Eigen::Vector3f& query, Bound&& bound, F&& f) const;
  static constexpr std::size_t kNone = ~std::size_t{0};

  float voxel_size_;
  float inverse_voxel_size_;
  float min_point_spacing_;
  std::size_t mask_;
  std::size_t max_voxels_;
  std::size_t voxel_count_ = 0;
  std::uint64_t dropped_points_ = 0;
  std::vector<Slot> slots_;
  // A voxel's points are read only up to its slot's count, so the storage
  // may be left unwritten (Storage::on_first_use).
  std::unique_ptr<Voxel[]> voxels_;
  std::vector<VoxelKey> doomed_;  // remove_far's scratch, reserved to capacity
};

}  // namespace adit::slam
