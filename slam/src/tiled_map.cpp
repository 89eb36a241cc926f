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

std::size_t TiledVoxelMap::add(std::span<const Eigen::Vector3f> points, std::span<const float> intensities,
                               double time_s) {
  const bool has_intensity = intensities.size() == points.size();
  const float inv_voxel = 1.0F / config_.voxel_m;
  const std::int32_t n = voxels_per_edge_;
  // Consecutive points mostly share a tile: look the tile up only when it changes.
  Tile* tile = nullptr;
  TileCoord current{};
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!p.allFinite()) continue;
    const TileCoord coord = tile_of(p);
    if (tile == nullptr || coord != current) {
      tile = &tiles_[coord];
      current = coord;
      origin = Eigen::Vector3f(static_cast<float>(coord.x), static_cast<float>(coord.y), static_cast<float>(coord.z)) *
               config_.tile_size_m;
    }
    const auto index_along = [&](float offset) {
      return std::clamp(static_cast<std::int32_t>(std::floor(offset * inv_voxel)), 0, n - 1);
    };
    const Eigen::Vector3f local = p - origin;
    const auto voxel = static_cast<std::uint32_t>((index_along(local.x()) * n + index_along(local.y())) * n +
                                                  index_along(local.z()));
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

}  // namespace adit::slam
