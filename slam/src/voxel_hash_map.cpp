#include "adit/slam/voxel_hash_map.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <span>

#include <Eigen/Eigenvalues>

namespace adit::slam {

VoxelHashMap::VoxelHashMap(float voxel_size_m, std::size_t capacity_voxels, float min_point_spacing_m, Storage storage)
    : voxel_size_(voxel_size_m),
      inverse_voxel_size_(1.0F / voxel_size_m),
      min_point_spacing_(std::max(min_point_spacing_m, 0.0F)),
      mask_(std::bit_ceil(std::max<std::size_t>(capacity_voxels, 16)) - 1),
      max_voxels_((mask_ + 1) * 3 / 4),
      slots_(mask_ + 1),
      voxels_(std::make_unique_for_overwrite<Voxel[]>(mask_ + 1)) {
  doomed_.reserve(slots_.size());
  if (storage == Storage::touched) {
    Voxel zero;
    zero.points.fill(Eigen::Vector3f::Zero());
    std::fill_n(voxels_.get(), slots_.size(), zero);
  }
}

std::size_t VoxelHashMap::home_of(const VoxelKey& key) const { return voxel_hash(key) & mask_; }

std::size_t VoxelHashMap::index_of(const VoxelKey& key) const {
  for (std::size_t i = home_of(key);; i = (i + 1) & mask_) {
    const Slot& s = slots_[i];
    if (s.count == 0 || s.key == key) return i;
  }
}

std::size_t VoxelHashMap::find(const VoxelKey& key) const {
  const std::size_t i = index_of(key);
  return slots_[i].count > 0 ? i : kNone;
}

std::size_t VoxelHashMap::find_or_insert(const VoxelKey& key) {
  const std::size_t i = index_of(key);
  if (slots_[i].count > 0) return i;
  if (voxel_count_ >= max_voxels_) return kNone;
  slots_[i].key = key;  // count stays 0 until the caller stores a point
  ++voxel_count_;
  return i;
}

void VoxelHashMap::add(std::span<const Eigen::Vector3f> points) {
  const float spacing_sq = min_point_spacing_ * min_point_spacing_;
  for (const Eigen::Vector3f& p : points) {
    const std::size_t i = find_or_insert(key_of(p));
    if (i == kNone || slots_[i].count >= kMaxPointsPerVoxel) {
      ++dropped_points_;
      continue;
    }
    const auto stored = std::span(voxels_[i].points).first(static_cast<std::size_t>(slots_[i].count));
    if (spacing_sq > 0.0F &&
        std::any_of(stored.begin(), stored.end(), [&](const Eigen::Vector3f& q) { return (q - p).squaredNorm() < spacing_sq; })) {
      ++dropped_points_;
      continue;
    }
    voxels_[i].points[static_cast<std::size_t>(slots_[i].count++)] = p;
  }
}

template <typename Bound, typename F>
void VoxelHashMap::visit_around(const Eigen::Vector3f& query, Bound&& bound, F&& f) const {
  const VoxelKey center = key_of(query);
  // The query's offset inside its voxel, per axis: the squared distance to a
  // neighbour voxel's box is the sum of the gaps on the axes where it differs.
  // Neighbours whose box is already farther than the bound are skipped.
  const Eigen::Vector3f low = query - Eigen::Vector3f(static_cast<float>(center.x), static_cast<float>(center.y),
                                                      static_cast<float>(center.z)) * voxel_size_;
  const Eigen::Vector3f high = Eigen::Vector3f::Constant(voxel_size_) - low;
  // Per axis, the side the query is nearer to (gap below half a voxel) and
  // the far side (gap above). Visiting the own voxel, then neighbours with
  // no far-side step, then one, two and three, fills a k-nearest search from
  // its closest voxels first, so its bound shrinks early and more of the far
  // voxels are skipped (the set found is the same in any order).
  // [axis][step: 0 same, 1 near side, 2 far side]: the key offset and the squared gap.
  std::array<std::array<int, 3>, 3> offset{};
  std::array<std::array<float, 3>, 3> gap{};
  for (int a = 0; a < 3; ++a) {
    const bool below = low[a] < high[a];
    const int near = below ? -1 : 1;
    const float near_gap = below ? low[a] : high[a];
    const float far_gap = below ? high[a] : low[a];
    offset[static_cast<std::size_t>(a)] = {0, near, -near};
    gap[static_cast<std::size_t>(a)] = {0.0F, near_gap * near_gap, far_gap * far_gap};
  }
  // The 27 (x, y, z) steps sorted by (far steps, near steps).
  static constexpr std::array<std::array<std::uint8_t, 3>, 27> kOrder = [] {
    std::array<std::array<std::uint8_t, 3>, 27> order{};
    std::size_t n = 0;
    for (int far = 0; far <= 3; ++far)
      for (int near = 0; near + far <= 3; ++near)
        for (std::uint8_t x = 0; x < 3; ++x)
          for (std::uint8_t y = 0; y < 3; ++y)
            for (std::uint8_t z = 0; z < 3; ++z) {
              const int fars = (x == 2) + (y == 2) + (z == 2);
              const int nears = (x == 1) + (y == 1) + (z == 1);
              if (fars == far && nears == near) order[n++] = {x, y, z};
            }
    return order;
  }();
  for (const auto& o : kOrder) {
    if (gap[0][o[0]] + gap[1][o[1]] + gap[2][o[2]] >= bound()) continue;
    const std::size_t s = find({center.x + offset[0][o[0]], center.y + offset[1][o[1]], center.z + offset[2][o[2]]});
    if (s != kNone) f(voxels_[s].points, slots_[s].count);
  }
}

MapNeighbor VoxelHashMap::nearest(const Eigen::Vector3f& query, float max_distance_m) const {
  MapNeighbor best;
  best.distance_sq = max_distance_m * max_distance_m;
  visit_around(query, [&] { return best.distance_sq; }, [&](const auto& points, int count) {
    for (int i = 0; i < count; ++i) {
      const Eigen::Vector3f& p = points[static_cast<std::size_t>(i)];
      const float d = (p - query).squaredNorm();
      if (d < best.distance_sq) {
        best.distance_sq = d;
        best.point = p;
        best.found = true;
      }
    }
  });
  if (!best.found) best.distance_sq = 0.0F;
  return best;
}

MapPlane VoxelHashMap::nearest_plane(const Eigen::Vector3f& query, int neighbors, float max_plane_error_m) const {
  // The k nearest within one voxel edge. Until k are found the bound is the
  // edge itself and their order does not matter: they are appended, and
  // sorted once when the k-th arrives; after that each closer point is
  // inserted in order (k is small). A sparse neighbourhood, fewer than k
  // within the edge (45 % of the searches on 64-beam scans), never sorts.
  const int k = std::clamp(neighbors, 3, kMaxPlaneNeighbors);
  std::array<float, kMaxPlaneNeighbors> d2;
  // Pointers into the map, not copies: the insertion sort moves one word per shift.
  std::array<const Eigen::Vector3f*, kMaxPlaneNeighbors> near{};
  d2.fill(voxel_size_ * voxel_size_);
  int found = 0;
  const auto insert_sorted = [&](int last, float d, const Eigen::Vector3f* p) {
    int j = last;
    for (; j > 0 && d2[static_cast<std::size_t>(j - 1)] > d; --j) {
      d2[static_cast<std::size_t>(j)] = d2[static_cast<std::size_t>(j - 1)];
      near[static_cast<std::size_t>(j)] = near[static_cast<std::size_t>(j - 1)];
    }
    d2[static_cast<std::size_t>(j)] = d;
    near[static_cast<std::size_t>(j)] = p;
  };
  visit_around(query, [&] { return d2[static_cast<std::size_t>(k - 1)]; }, [&](const auto& points, int count) {
    for (int i = 0; i < count; ++i) {
      const Eigen::Vector3f& p = points[static_cast<std::size_t>(i)];
      const float d = (p - query).squaredNorm();
      if (d >= d2[static_cast<std::size_t>(k - 1)]) continue;
      if (found < k) {
        d2[static_cast<std::size_t>(found)] = d;
        near[static_cast<std::size_t>(found)] = &p;
        if (++found == k)
          for (int j = 1; j < k; ++j) insert_sorted(j, d2[static_cast<std::size_t>(j)], near[static_cast<std::size_t>(j)]);
        continue;
      }
      insert_sorted(k - 1, d, &p);
    }
  });
  MapPlane plane;
  if (found < k) return plane;
  // The plane: the covariance's eigenvector of the smallest eigenvalue
  // (relative to the first neighbour, in double, for precision far from the origin).
  const auto used = std::span(near).first(static_cast<std::size_t>(k));
  const Eigen::Vector3f origin = *near[0];
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto* p : used) mean += (*p - origin).cast<double>();
  mean /= k;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const auto* p : used) {
    const Eigen::Vector3d d = (*p - origin).cast<double>() - mean;
    covariance.noalias() += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(covariance);
  const Eigen::Vector3d& lambda = solver.eigenvalues();  // ascending
  // Five points along one ring are a line: their "normal" would be any
  // direction across it. Flat means thin across, wide along two directions.
  constexpr double kFlatness = 0.1;  // λ0 / λ1
  if (!(lambda(0) < kFlatness * lambda(1))) return plane;
  const Eigen::Vector3d normal = solver.eigenvectors().col(0);
  for (const auto* p : used)
    if (std::abs(normal.dot((*p - origin).cast<double>() - mean)) > max_plane_error_m) return plane;
  plane.point = origin + mean.cast<float>();
  plane.normal = normal.cast<float>();
  plane.found = true;
  return plane;
}

void VoxelHashMap::prefetch_around(const Eigen::Vector3f& query) const {
  const VoxelKey c = key_of(query);
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) __builtin_prefetch(&slots_[home_of({c.x + dx, c.y + dy, c.z + dz})]);
}

void VoxelHashMap::remove_far(const Eigen::Vector3f& origin, float max_distance_m) {
  const float max_sq = max_distance_m * max_distance_m;
  // Collect keys, not slot indices: each erase shifts later slots back.
  doomed_.clear();
  // The voxel's box decides for all but the voxels the sphere cuts through:
  // entirely outside, the first point is too; entirely inside, it is not.
  // Only the rest read their first point (the slots are one compact table;
  // the points are 30 MB). The margin absorbs float rounding at the box edges.
  const float margin = 1e-3F * voxel_size_ + 1e-3F;
  const float outside_sq = (max_distance_m + margin) * (max_distance_m + margin);
  const float inside = std::max(max_distance_m - margin, 0.0F);
  const float inside_sq = inside * inside;
  for (std::size_t s = 0; s < slots_.size(); ++s) {
    if (slots_[s].count == 0) continue;
    const VoxelKey& key = slots_[s].key;
    const Eigen::Vector3f low =
        Eigen::Vector3f(static_cast<float>(key.x), static_cast<float>(key.y), static_cast<float>(key.z)) * voxel_size_ -
        origin;
    const Eigen::Vector3f high = low + Eigen::Vector3f::Constant(voxel_size_);
    const Eigen::Vector3f gap = low.cwiseMax(-high).cwiseMax(0.0F);          // per axis, 0 when the origin is inside
    const Eigen::Vector3f reach = low.cwiseAbs().cwiseMax(high.cwiseAbs());  // the farthest corner, per axis
    const bool far = gap.squaredNorm() > outside_sq ||
                     (reach.squaredNorm() >= inside_sq && (voxels_[s].points[0] - origin).squaredNorm() > max_sq);
    if (far) doomed_.push_back(key);
  }
  for (const VoxelKey& key : doomed_) erase_at(index_of(key));
}

void VoxelHashMap::erase_at(std::size_t index) {
  // Backward-shift deletion: pull later members of the probe run back so
  // lookups never stop early at the hole (no tombstones needed).
  std::size_t hole = index;
  for (std::size_t j = (hole + 1) & mask_; slots_[j].count > 0; j = (j + 1) & mask_) {
    const std::size_t home = home_of(slots_[j].key);
    // Move j into the hole unless its home lies cyclically in (hole, j].
    const bool home_between = hole <= j ? (hole < home && home <= j) : (hole < home || home <= j);
    if (!home_between) {
      slots_[hole] = slots_[j];
      voxels_[hole] = voxels_[j];
      hole = j;
    }
  }
  slots_[hole].count = 0;
  --voxel_count_;
}

void VoxelHashMap::clear() {
  for (Slot& s : slots_) s.count = 0;
  voxel_count_ = 0;
  dropped_points_ = 0;
}

std::size_t VoxelHashMap::point_count() const {
  std::size_t n = 0;
  for (const Slot& s : slots_) n += static_cast<std::size_t>(s.count);
  return n;
}

}  // namespace adit::slam
