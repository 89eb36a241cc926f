#include "adit/slam/tiled_map.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace adit::slam {

std::string tiled_map_config_problem(const TiledMapConfig& config) {
  if (!(config.tile_size_m > 0.0F) || !std::isfinite(config.tile_size_m)) return "tile size must be positive";
  if (!(config.voxel_m > 0.0F) || !std::isfinite(config.voxel_m)) return "voxel size must be positive";
  if (config.voxel_m > config.tile_size_m) return "voxel size must not exceed the tile size";
  if (std::ceil(config.tile_size_m / config.voxel_m) > 1600.0F)
    return "tile size / voxel size must be at most 1600 (voxel indices are 32-bit)";
  return "";
}

TiledVoxelMap::TiledVoxelMap(const TiledMapConfig& config)
    : config_(config), voxels_per_edge_(static_cast<std::int32_t>(std::ceil(config.tile_size_m / config.voxel_m))) {
  if (const std::string problem = tiled_map_config_problem(config); !problem.empty())
    throw std::invalid_argument("tiled map: " + problem);
}

TileCoord TiledVoxelMap::tile_of(const Eigen::Vector3f& p) const {
  const float inv = 1.0F / config_.tile_size_m;
  return {static_cast<std::int32_t>(std::floor(p.x() * inv)), static_cast<std::int32_t>(std::floor(p.y() * inv)),
          static_cast<std::int32_t>(std::floor(p.z() * inv))};
}

Eigen::Vector3f TiledVoxelMap::origin_of(const TileCoord& coord) const {
  return Eigen::Vector3f(static_cast<float>(coord.x), static_cast<float>(coord.y), static_cast<float>(coord.z)) *
         config_.tile_size_m;
}

std::uint32_t TiledVoxelMap::voxel_of(const Eigen::Vector3f& p, const Eigen::Vector3f& origin) const {
  const float inv_voxel = 1.0F / config_.voxel_m;
  const std::int32_t n = voxels_per_edge_;
  const auto index_along = [&](float offset) {
    return std::clamp(static_cast<std::int32_t>(std::floor(offset * inv_voxel)), 0, n - 1);
  };
  const Eigen::Vector3f local = p - origin;
  return static_cast<std::uint32_t>((index_along(local.x()) * n + index_along(local.y())) * n +
                                    index_along(local.z()));
}

TiledVoxelMap::Tile& TiledVoxelMap::new_tile(const TileCoord& coord) { return tiles_[coord]; }

std::size_t TiledVoxelMap::add(std::span<const Eigen::Vector3f> points, std::span<const float> intensities,
                               double time_s) {
  const bool has_intensity = intensities.size() == points.size();
  // Consecutive points mostly share a tile: look the tile up only when it changes.
  Tile* tile = nullptr;
  bool evicted = false;
  TileCoord current{};
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!p.allFinite()) continue;
    const TileCoord coord = tile_of(p);
    if ((tile == nullptr && !evicted) || coord != current) {
      current = coord;
      evicted = !evicted_.empty() && evicted_.contains(coord);
      tile = evicted ? nullptr : &new_tile(coord);
      origin = origin_of(coord);
    }
    if (evicted) {  // its points are elsewhere (the caller's store): adding here would duplicate voxels
      ++dropped_in_evicted_;
      continue;
    }
    const std::uint32_t voxel = voxel_of(p, origin);
    if (!tile->stored.empty()) {  // a restored tile: its stored voxels are in the map already
      const auto [block, bit] = block_of(voxel);
      if (tile->stored.contains(block, bit)) continue;
    }
    const auto next = static_cast<std::uint32_t>(tile->candidates.size());
    const std::uint32_t candidate = tile->voxels.find_or_insert(voxel, next);
    if (candidate == next) {
      tile->candidates.push_back({p, has_intensity ? intensities[i] : 0.0F, time_s});
      tile->hits.push_back(0);
      ++candidates_;
    }
    std::uint8_t& hits = tile->hits[candidate];
    if (hits == 255) continue;
    if (++hits != std::max<std::uint8_t>(config_.min_hits, 1)) continue;
    tile->points.push_back(tile->candidates[candidate]);  // confirmed now
    changed_.insert(coord);
    ++kept;
  }
  size_ += kept;
  return kept;
}

TiledVoxelMap::Evicted TiledVoxelMap::evict(const TileCoord& coord) {
  const auto it = tiles_.find(coord);
  if (it == tiles_.end()) return {};
  Tile& tile = it->second;
  const std::size_t confirmed = tile.points.size();
  Evicted out{std::move(tile.points), changed_.erase(coord) > 0};
  candidates_ -= tile.candidates.size();
  lost_candidates_ += tile.candidates.size() - confirmed;
  stored_size_ -= tile.stored_points;
  evicted_[coord] = tile.stored_points + confirmed;
  evicted_size_ += tile.stored_points + confirmed;
  tiles_.erase(it);
  return out;
}

void TiledVoxelMap::restore(const TileCoord& coord, std::span<const MapSample> points) {
  if (tiles_.contains(coord)) return;
  if (const auto it = evicted_.find(coord); it != evicted_.end()) {
    size_ -= it->second;  // replaced by what comes back (the same points, unless the store lost some)
    evicted_size_ -= it->second;
    evicted_.erase(it);
  }
  Tile& tile = new_tile(coord);
  const Eigen::Vector3f origin = origin_of(coord);
  for (const MapSample& s : points) {
    const auto [block, bit] = block_of(voxel_of(s.position, origin));
    tile.stored.insert(block, bit);
  }
  tile.stored_points = points.size();
  stored_size_ += points.size();
  size_ += points.size();
}

std::pair<std::uint32_t, std::uint32_t> TiledVoxelMap::block_of(std::uint32_t voxel) const {
  const auto n = static_cast<std::uint32_t>(voxels_per_edge_);
  const std::uint32_t blocks_per_edge = (n + 7) / 8;
  const std::uint32_t z = voxel % n;
  const std::uint32_t y = (voxel / n) % n;
  const std::uint32_t x = voxel / (n * n);
  return {((x >> 3) * blocks_per_edge + (y >> 3)) * blocks_per_edge + (z >> 3),
          ((x & 7U) << 6) | ((y & 7U) << 3) | (z & 7U)};
}

void TiledVoxelMap::VoxelBits::insert(std::uint32_t block, std::uint32_t bit) {
  const auto next = static_cast<std::uint32_t>(bitmaps_.size());
  const std::uint32_t at = blocks_.find_or_insert(block, next);
  if (at == next) bitmaps_.push_back(Bitmap{});
  bitmaps_[at][bit >> 6] |= std::uint64_t{1} << (bit & 63U);
}

bool TiledVoxelMap::VoxelBits::contains(std::uint32_t block, std::uint32_t bit) const {
  const std::uint32_t at = blocks_.find(block);
  return at != VoxelIndex::kEmpty && (bitmaps_[at][bit >> 6] >> (bit & 63U) & 1U) != 0;
}

void TiledVoxelMap::holds(std::span<const Eigen::Vector3f> points, std::vector<std::uint8_t>& held,
                          int reach_voxels) const {
  held.assign(points.size(), 0);
  const Tile* tile = nullptr;
  TileCoord current{};
  bool looked_up = false;
  const std::uint8_t confirmed = std::max<std::uint8_t>(config_.min_hits, 1);
  const auto holds_voxel_of = [&](const Eigen::Vector3f& p) {
    const TileCoord coord = tile_of(p);
    if (!looked_up || coord != current) {
      looked_up = true;
      current = coord;
      const auto it = tiles_.find(coord);
      tile = it == tiles_.end() ? nullptr : &it->second;
    }
    if (tile == nullptr) return false;
    const std::uint32_t voxel = voxel_of(p, origin_of(coord));
    if (!tile->stored.empty()) {
      const auto [block, bit] = block_of(voxel);
      if (tile->stored.contains(block, bit)) return true;
    }
    const std::uint32_t candidate = tile->voxels.find(voxel);
    return candidate != VoxelIndex::kEmpty && tile->hits[candidate] >= confirmed;
  };
  const int reach = std::max(reach_voxels, 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!p.allFinite()) continue;
    bool found = holds_voxel_of(p);
    for (int dx = -reach; dx <= reach && !found; ++dx)
      for (int dy = -reach; dy <= reach && !found; ++dy)
        for (int dz = -reach; dz <= reach && !found; ++dz)
          if (dx != 0 || dy != 0 || dz != 0)
            found = holds_voxel_of(p + config_.voxel_m * Eigen::Vector3f(static_cast<float>(dx), static_cast<float>(dy),
                                                                          static_cast<float>(dz)));
    held[i] = found ? 1 : 0;
  }
}

std::vector<TileCoord> TiledVoxelMap::evicted_hit_by(std::span<const Eigen::Vector3f> points) const {
  std::set<TileCoord> hit;
  if (evicted_.empty()) return {};
  bool first = true;
  TileCoord current{};
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    const TileCoord coord = tile_of(p);
    if (!first && coord == current) continue;
    first = false;
    current = coord;
    if (evicted_.contains(coord)) hit.insert(coord);
  }
  return {hit.begin(), hit.end()};
}

std::size_t TiledVoxelMap::memory_bytes() const {
  std::size_t bytes = 0;
  for (const auto& [coord, tile] : tiles_)
    bytes += sizeof(coord) + sizeof(tile) + 4 * sizeof(void*) +  // std::map node
             compactable_bytes(tile) + tile.stored.memory_bytes();
  return bytes;
}

std::size_t TiledVoxelMap::compactable_bytes(const TileCoord& coord) const {
  const auto it = tiles_.find(coord);
  return it == tiles_.end() ? 0 : compactable_bytes(it->second);
}

std::size_t TiledVoxelMap::compactable_bytes(const Tile& tile) {
  return tile.voxels.memory_bytes() + tile.candidates.capacity() * sizeof(MapSample) + tile.hits.capacity() +
         tile.points.capacity() * sizeof(MapSample);
}

std::uint32_t TiledVoxelMap::VoxelIndex::find_or_insert(std::uint32_t voxel, std::uint32_t next) {
  if (2 * (size_ + 1) > slots_.size()) grow();
  const std::size_t mask = slots_.size() - 1;
  for (std::size_t i = (voxel * 2654435761U) & mask;; i = (i + 1) & mask) {
    if (slots_[i].voxel == voxel) return slots_[i].candidate;
    if (slots_[i].voxel == kEmpty) {
      slots_[i] = {voxel, next};
      ++size_;
      return next;
    }
  }
}

std::uint32_t TiledVoxelMap::VoxelIndex::find(std::uint32_t voxel) const {
  if (slots_.empty()) return kEmpty;
  const std::size_t mask = slots_.size() - 1;
  for (std::size_t i = (voxel * 2654435761U) & mask;; i = (i + 1) & mask) {
    if (slots_[i].voxel == voxel) return slots_[i].candidate;
    if (slots_[i].voxel == kEmpty) return kEmpty;
  }
}

void TiledVoxelMap::VoxelIndex::grow() {
  std::vector<Slot> old = std::move(slots_);
  slots_.assign(old.empty() ? 64 : 2 * old.size(), Slot{});
  size_ = 0;
  for (const Slot& s : old)
    if (s.voxel != kEmpty) find_or_insert(s.voxel, s.candidate);
}

std::vector<TileCoord> TiledVoxelMap::take_changed() {
  std::vector<TileCoord> out(changed_.begin(), changed_.end());
  changed_.clear();
  return out;
}

std::span<const MapSample> TiledVoxelMap::tile(const TileCoord& coord) const {
  const auto it = tiles_.find(coord);
  if (it == tiles_.end()) return {};
  return it->second.points;
}

std::vector<TileCoord> TiledVoxelMap::tile_coords() const {
  std::vector<TileCoord> out;
  out.reserve(tiles_.size());
  for (const auto& [coord, tile] : tiles_) out.push_back(coord);
  return out;
}

std::vector<TileCoord> TiledVoxelMap::evicted_coords() const {
  std::vector<TileCoord> out;
  out.reserve(evicted_.size());
  for (const auto& [coord, points] : evicted_) out.push_back(coord);
  return out;
}

std::size_t TiledVoxelMap::held_voxels(const TileCoord& coord) const {
  const auto it = tiles_.find(coord);
  return it == tiles_.end() ? 0 : it->second.candidates.size();
}

std::size_t TiledVoxelMap::stored_points(const TileCoord& coord) const {
  const auto it = tiles_.find(coord);
  return it == tiles_.end() ? 0 : it->second.stored_points;
}

std::size_t TiledVoxelMap::evicted_points(const TileCoord& coord) const {
  const auto it = evicted_.find(coord);
  return it == evicted_.end() ? 0 : it->second;
}

float distance_to_tile(const TileCoord& coord, float tile_size_m, const Eigen::Vector3f& p) {
  const Eigen::Vector3f lo =
      Eigen::Vector3f(static_cast<float>(coord.x), static_cast<float>(coord.y), static_cast<float>(coord.z)) *
      tile_size_m;
  const Eigen::Vector3f hi = lo + Eigen::Vector3f::Constant(tile_size_m);
  // Per axis, how far p lies outside [lo, hi]; the norm is the distance to the box.
  const Eigen::Vector3f outside = (lo - p).cwiseMax(p - hi).cwiseMax(0.0F);
  return outside.norm();
}

std::vector<TileCoord> TileEviction::cold_tiles(const TiledVoxelMap& map, const Eigen::Vector3f& sensor) {
  std::vector<TileCoord> cold;
  if (config_.after_keyframes <= 0) return cold;
  std::map<TileCoord, int> far_for;
  for (const TileCoord& coord : map.tile_coords()) {
    if (distance_to_tile(coord, map.config().tile_size_m, sensor) <= config_.radius_m) continue;
    const auto it = far_for_.find(coord);
    const int n = (it == far_for_.end() ? 0 : it->second) + 1;
    if (n >= config_.after_keyframes) cold.push_back(coord);
    else far_for.emplace(coord, n);
  }
  far_for_ = std::move(far_for);  // near, evicted or gone tiles start again from zero
  return cold;
}

std::vector<TileCoord> TileEviction::crowded_tiles(const TiledVoxelMap& map) const {
  std::vector<TileCoord> crowded;
  std::vector<std::pair<std::size_t, TileCoord>> others;  // (bytes a compaction frees, tile) of the rest
  std::size_t bytes = config_.resident_bytes > 0 ? map.memory_bytes() : 0;
  for (const TileCoord& coord : map.tile_coords()) {
    const std::size_t freed = map.compactable_bytes(coord);
    if (config_.compact_voxels > 0 && map.held_voxels(coord) > config_.compact_voxels) {
      crowded.push_back(coord);
      bytes -= std::min(bytes, freed);
    } else if (freed > 0) {
      others.emplace_back(freed, coord);
    }
  }
  if (bytes <= config_.resident_bytes) return crowded;
  // Largest first; ties in coordinate order, so the choice does not depend on the sort.
  std::sort(others.begin(), others.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  const std::size_t target = config_.resident_bytes / 4 * 3;
  for (const auto& [freed, coord] : others) {
    if (bytes <= target) break;
    crowded.push_back(coord);
    bytes -= std::min(bytes, freed);
  }
  std::sort(crowded.begin(), crowded.end());
  return crowded;
}

}  // namespace adit::slam
