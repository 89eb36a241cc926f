// The live 2D occupancy grid: a band around the sensor's height, obstacles
// per cell, free rays per bearing, log-odds per cell. (live_grid.hpp)
#include "adit/slam/live_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include <zstd.h>

namespace adit::slam {
namespace {

// Log-odds ×1000 (int16): OctoMap's hit 0.7, miss 0.4, clamping 0.12 / 0.97;
// map_saver's occupied 0.65 and free 0.196 thresholds.
constexpr std::int16_t kHit = 847;        // ln(0.7 / 0.3)
constexpr std::int16_t kMiss = -405;      // ln(0.4 / 0.6)
constexpr std::int16_t kMin = -1992;      // ln(0.12 / 0.88)
constexpr std::int16_t kMax = 3476;       // ln(0.97 / 0.03)
constexpr std::int16_t kOccupiedAt = 619;   // ln(0.65 / 0.35)
constexpr std::int16_t kFreeAt = -1411;     // ln(0.196 / 0.804)

std::int8_t value_of(std::int16_t log_odds) {
  if (log_odds >= kOccupiedAt) return kGridOccupied;
  if (log_odds <= kFreeAt) return kGridFree;
  return kGridUnknown;
}

std::int64_t floor_div(std::int64_t a, std::int64_t n) { return a >= 0 ? a / n : -((-a + n - 1) / n); }

}  // namespace

LiveGrid::LiveGrid(const LiveGridConfig& config)
    : config_(config),
      inv_resolution_(1.0F / config.resolution_m),
      tilt_tan_(std::tan(config.tilt_tolerance_deg * std::numbers::pi_v<float> / 180.0F)) {
  if (!(config.resolution_m > 0.0F) || config.patch_cells < 1 || config.bearings < 1 || !(config.max_range_m > 0.0F))
    throw std::invalid_argument("LiveGrid: resolution, range, bearings and patch size must be positive");
  rays_.resize(static_cast<std::size_t>(config.bearings));
}

LiveGrid::Patch& LiveGrid::patch_at(GridPatchCoord c) {
  if (last_patch_ != nullptr && c == last_coord_) return *last_patch_;
  auto [it, added] = patches_.try_emplace(key(c));
  const auto cells = static_cast<std::size_t>(config_.patch_cells) * static_cast<std::size_t>(config_.patch_cells);
  if (added) {
    it->second.log_odds.assign(cells, 0);
    it->second.stamp.assign(cells, 0);
  } else if (!it->second.frozen.empty()) {
    thaw_into(it->second.frozen, it->second.log_odds);
    it->second.frozen = std::vector<std::uint8_t>();
    it->second.stamp.assign(cells, 0);  // 0 is never a scan's stamp: every cell may be updated
    --frozen_;
    ++counts_.thaws;
  }
  last_patch_ = &it->second;  // unordered_map keeps its elements where they are
  last_coord_ = c;
  return it->second;
}

bool LiveGrid::update(Patch& p, std::size_t cell, std::int16_t delta) {
  if (p.stamp[cell] == scan_stamp_) return false;
  p.stamp[cell] = scan_stamp_;
  std::int16_t& l = p.log_odds[cell];
  const std::int8_t before = value_of(l);
  // A ray that passes a cell read as occupied has most often grazed a wall on
  // its way to the wall's next point: that miss counts half (decision 045).
  if (delta < 0 && before == kGridOccupied) delta = static_cast<std::int16_t>(delta / 2);
  l = static_cast<std::int16_t>(std::clamp<int>(l + delta, kMin, kMax));
  if (value_of(l) != before) p.changed = true;
  return true;
}

// The cells from `from` to `to` (map xy) by Amanatides & Woo's traversal
// (1987), each passed once; cells hit this scan were stamped first and keep
// their hit. The walk keeps its patch and the cell's place in it as it steps,
// so a cell costs no division and no lookup.
void LiveGrid::trace_free(const Eigen::Vector2f& from, const Eigen::Vector2f& to) {
  const Eigen::Vector2f a = from * inv_resolution_;
  const Eigen::Vector2f b = to * inv_resolution_;
  const auto i0 = static_cast<std::int64_t>(std::floor(a.x()));
  const auto j0 = static_cast<std::int64_t>(std::floor(a.y()));
  const auto end_i = static_cast<std::int64_t>(std::floor(b.x()));
  const auto end_j = static_cast<std::int64_t>(std::floor(b.y()));
  const Eigen::Vector2f d = b - a;
  const int step_i = d.x() > 0 ? 1 : -1;
  const int step_j = d.y() > 0 ? 1 : -1;
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const float delta_i = d.x() != 0 ? std::abs(1.0F / d.x()) : kInf;
  const float delta_j = d.y() != 0 ? std::abs(1.0F / d.y()) : kInf;
  float t_i = d.x() != 0 ? (step_i > 0 ? static_cast<float>(i0 + 1) - a.x() : a.x() - static_cast<float>(i0)) * delta_i : kInf;
  float t_j = d.y() != 0 ? (step_j > 0 ? static_cast<float>(j0 + 1) - a.y() : a.y() - static_cast<float>(j0)) * delta_j : kInf;
  const std::int64_t n = config_.patch_cells;
  GridPatchCoord patch{static_cast<std::int32_t>(floor_div(i0, n)), static_cast<std::int32_t>(floor_div(j0, n))};
  std::int64_t li = i0 - patch.x * n;  // the cell within its patch
  std::int64_t lj = j0 - patch.y * n;
  Patch* p = &patch_at(patch);
  // |end - start| cells in each axis bound the walk (float rounding at a corner).
  const std::int64_t steps = std::abs(end_i - i0) + std::abs(end_j - j0);
  for (std::int64_t s = 0;; ++s) {
    if (update(*p, static_cast<std::size_t>(lj * n + li), kMiss)) ++counts_.miss_updates;
    if (s >= steps) break;
    if (t_i < t_j) {
      t_i += delta_i;
      li += step_i;
      if (li < 0 || li >= n) {
        li -= step_i * n;
        patch.x += step_i;
        p = &patch_at(patch);
      }
    } else {
      t_j += delta_j;
      lj += step_j;
      if (lj < 0 || lj >= n) {
        lj -= step_j * n;
        patch.y += step_j;
        p = &patch_at(patch);
      }
    }
  }
}

// A monotonic stand-in for atan2 in [0, 4) (the "diamond angle"): a quarter
// turn per unit, its bins 0.64-1.27 times as wide as equal angles, at the
// cost of a division instead of an arctangent.
float LiveGrid::pseudo_angle(float x, float y) {
  if (y >= 0) return x >= 0 ? y / (x + y) : 1.0F - x / (y - x);
  return x < 0 ? 2.0F - y / (-x - y) : 3.0F + x / (x - y);
}

void LiveGrid::insert(const Eigen::Vector3f& origin, std::span<const Eigen::Vector3f> points) {
  if (++scan_stamp_ == 0) ++scan_stamp_;  // 0 is a new cell's stamp
  ++counts_.scans;
  for (Ray& r : rays_) r = Ray{};
  const float max2 = config_.max_range_m * config_.max_range_m;
  const float min_range = config_.resolution_m;
  const float bins_per_unit = static_cast<float>(config_.bearings) / 4.0F;
  const Eigen::Vector2f o = origin.head<2>();
  // Obstacles first: each cell of the band hit this scan counts once, as hit.
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    const Eigen::Vector2f d = p.head<2>() - o;
    const float r2 = d.squaredNorm();
    if (r2 > max2 || r2 < min_range * min_range) continue;
    const float r = std::sqrt(r2);
    const float dz = p.z() - origin.z();
    auto bin = static_cast<int>(pseudo_angle(d.x(), d.y()) * bins_per_unit);
    bin = std::clamp(bin, 0, config_.bearings - 1);
    Ray& ray = rays_[static_cast<std::size_t>(bin)];
    const float margin = r * tilt_tan_;
    if (dz >= -config_.band_below_m + margin && dz <= config_.band_above_m - margin) {
      const auto i = static_cast<std::int64_t>(std::floor(p.x() * inv_resolution_));
      const auto j = static_cast<std::int64_t>(std::floor(p.y() * inv_resolution_));
      const std::int64_t n = config_.patch_cells;
      const GridPatchCoord c{static_cast<std::int32_t>(floor_div(i, n)), static_cast<std::int32_t>(floor_div(j, n))};
      if (update(patch_at(c), static_cast<std::size_t>((j - c.y * n) * n + (i - c.x * n)), kHit)) ++counts_.hit_updates;
      if (ray.hit_range == 0.0F || r < ray.hit_range) {
        ray.hit_range = r;
        ray.hit_dir = d / r;
      }
    } else if (dz < -config_.band_below_m || dz > config_.band_above_m) {
      // Where the ray from the sensor left the band (its height is linear in r).
      const float edge = dz > 0 ? config_.band_above_m : config_.band_below_m;
      const float reach = r * edge / std::abs(dz);
      if (reach > ray.free_range) {
        ray.free_range = reach;
        ray.free_dir = d / r;
      }
    }
  }
  // Then the free rays: to the nearest obstacle per bearing, or as far as the
  // band was seen through where there was none.
  for (const Ray& ray : rays_) {
    if (ray.hit_range > 0.0F) {
      trace_free(o, o + ray.hit_dir * ray.hit_range);
    } else if (ray.free_range > min_range) {
      trace_free(o, o + ray.free_dir * ray.free_range);
    }
  }
  if (config_.freeze_far_patches) freeze_far(o);
}

// Log-odds into `frozen` (zstd level 1: a patch of 32 kB in some 50 µs).
void LiveGrid::freeze(Patch& p) {
  const std::size_t bytes = p.log_odds.size() * sizeof(std::int16_t);
  std::vector<std::uint8_t> packed(ZSTD_compressBound(bytes));
  const std::size_t size = ZSTD_compress(packed.data(), packed.size(), p.log_odds.data(), bytes, 1);
  if (ZSTD_isError(size)) return;  // stays as it is
  packed.resize(size);
  packed.shrink_to_fit();
  p.frozen = std::move(packed);
  // A moved-in empty vector frees the buffer (assigning {} would keep it).
  p.log_odds = std::vector<std::int16_t>();
  p.stamp = std::vector<std::uint16_t>();
  ++frozen_;
  ++counts_.freezes;
}

// A frozen patch's log-odds back (a frame this grid wrote: its size is known).
void LiveGrid::thaw_into(const std::vector<std::uint8_t>& frozen, std::vector<std::int16_t>& log_odds) const {
  const auto cells = static_cast<std::size_t>(config_.patch_cells) * static_cast<std::size_t>(config_.patch_cells);
  log_odds.assign(cells, 0);
  const std::size_t size = ZSTD_decompress(log_odds.data(), cells * sizeof(std::int16_t), frozen.data(), frozen.size());
  if (ZSTD_isError(size) || size != cells * sizeof(std::int16_t))
    throw std::logic_error(std::string("LiveGrid: a frozen patch does not decompress: ") + ZSTD_getErrorName(size));
}

void LiveGrid::freeze_far(const Eigen::Vector2f& origin) {
  // A patch wholly beyond the rays' reach plus one patch's width (so that one
  // on the edge does not freeze and thaw as the sensor sways).
  const float side = static_cast<float>(config_.patch_cells) * config_.resolution_m;
  const float reach = config_.max_range_m + side;
  bool froze = false;
  for (auto& [k, p] : patches_) {
    if (!p.frozen.empty()) continue;
    const GridPatchCoord c = coord_of(k);
    const Eigen::Vector2f low(static_cast<float>(c.x) * side, static_cast<float>(c.y) * side);
    const Eigen::Vector2f nearest = origin.cwiseMax(low).cwiseMin(low + Eigen::Vector2f::Constant(side));
    if ((nearest - origin).squaredNorm() <= reach * reach) continue;
    freeze(p);
    froze = true;
  }
  if (froze) last_patch_ = nullptr;
}

std::vector<GridPatchCoord> LiveGrid::take_changed() {
  std::vector<GridPatchCoord> changed;
  for (auto& [k, p] : patches_) {
    if (!p.changed) continue;
    p.changed = false;
    ++p.version;
    changed.push_back(coord_of(k));
  }
  std::sort(changed.begin(), changed.end());
  return changed;
}

std::vector<GridPatchCoord> LiveGrid::patch_coords() const {
  std::vector<GridPatchCoord> coords;
  coords.reserve(patches_.size());
  for (const auto& [k, p] : patches_) coords.push_back(coord_of(k));
  std::sort(coords.begin(), coords.end());
  return coords;
}

void LiveGrid::read(GridPatchCoord patch, std::span<std::int8_t> out) const {
  const auto cells = static_cast<std::size_t>(config_.patch_cells) * static_cast<std::size_t>(config_.patch_cells);
  if (out.size() < cells) throw std::invalid_argument("LiveGrid::read: the output holds fewer than a patch's cells");
  const auto it = patches_.find(key(patch));
  if (it == patches_.end()) {
    std::fill_n(out.begin(), cells, kGridUnknown);
    return;
  }
  if (!it->second.frozen.empty()) {
    std::vector<std::int16_t> log_odds;
    thaw_into(it->second.frozen, log_odds);
    std::transform(log_odds.begin(), log_odds.end(), out.begin(), value_of);
    return;
  }
  std::transform(it->second.log_odds.begin(), it->second.log_odds.end(), out.begin(), value_of);
}

std::int32_t LiveGrid::version(GridPatchCoord patch) const {
  const auto it = patches_.find(key(patch));
  return it == patches_.end() ? 0 : it->second.version;
}

std::size_t LiveGrid::memory_bytes() const {
  std::size_t bytes = rays_.capacity() * sizeof(Ray);
  for (const auto& [k, p] : patches_)
    bytes += sizeof(p) + sizeof(k) + p.log_odds.capacity() * sizeof(std::int16_t) +
             p.stamp.capacity() * sizeof(std::uint16_t) + p.frozen.capacity();
  return bytes;
}

}  // namespace adit::slam
