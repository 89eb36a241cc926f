// A session's map files, tile by tile (map_files.hpp).
#include "adit/daemon/map_files.hpp"

#include <algorithm>
#include <cmath>

#include "adit/products/grid_io.hpp"
#include "adit/protocol/grid_mosaic.hpp"
#include "adit/protocol/map_export.hpp"
#include "adit/slam/live_grid.hpp"

namespace adit::daemon {

std::uintmax_t write_live_grid(const std::filesystem::path& stem, const slam::LiveGrid& grid) {
  const slam::LiveGridConfig& c = grid.config();
  protocol::GridMosaic mosaic;
  for (const slam::GridPatchCoord& p : grid.patch_coords()) {
    std::vector<std::int8_t> cells(static_cast<std::size_t>(c.patch_cells) * static_cast<std::size_t>(c.patch_cells));
    grid.read(p, cells);
    mosaic.put("", c.resolution_m, c.patch_cells, p.x, p.y, 1, std::move(cells));
  }
  if (mosaic.patch_count() == 0) return 0;
  return products::write_grid(stem, products::grid_of(mosaic.image()));
}

std::array<double, 3> map_corner(const std::vector<slam::TileCoord>& coords, double tile_size_m, double margin_m,
                                 const Eigen::Isometry3d& placed_by) {
  Eigen::Vector3d corner = Eigen::Vector3d::Zero();
  bool first = true;
  for (const slam::TileCoord& c : coords) {
    const Eigen::Vector3d low(c.x * tile_size_m, c.y * tile_size_m, c.z * tile_size_m);
    for (int k = 0; k < 8; ++k) {  // a rotated tile's lowest point is one of its corners
      const Eigen::Vector3d offset((k & 1) != 0 ? tile_size_m : 0.0, (k & 2) != 0 ? tile_size_m : 0.0,
                                   (k & 4) != 0 ? tile_size_m : 0.0);
      const Eigen::Vector3d p = placed_by * (low + offset);
      corner = first ? p : corner.cwiseMin(p);
      first = false;
    }
  }
  return {std::floor(corner.x() - margin_m), std::floor(corner.y() - margin_m), std::floor(corner.z() - margin_m)};
}

std::vector<std::string> write_map_files(
    const std::filesystem::path& dir, const std::vector<std::string>& formats, std::uint64_t n_points,
    const std::array<double, 3>& corner, const std::vector<slam::TileCoord>& coords,
    const std::function<void(const slam::TileCoord&, std::vector<protocol::MapPoint>&)>& read) {
  std::vector<protocol::MapFileWriter> writers;
  std::vector<std::string> names;
  writers.reserve(formats.size());
  for (const std::string& name : formats) {
    const std::filesystem::path file = dir / ("map." + name);
    writers.emplace_back(file, *protocol::parse_map_format(name), n_points, corner);
    names.push_back(file.filename().string());
  }
  std::vector<protocol::MapPoint> points;
  for (const slam::TileCoord& c : coords) {
    read(c, points);
    for (protocol::MapFileWriter& w : writers) w.write(points);
  }
  for (protocol::MapFileWriter& w : writers) w.finish();
  return names;
}

}  // namespace adit::daemon
