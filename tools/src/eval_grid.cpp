// adit eval grid: a 2D occupancy grid (map_server PGM + YAML, as `adit
// products` writes it) against the simulator's scene: IoU of free and of
// occupied cells over what the path could see (eval/grid_truth.hpp).

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/eval/grid_truth.hpp"
#include "adit/products/grid_io.hpp"
#include "adit/products/raster_image.hpp"
#include "eval_commands.hpp"

namespace adit::tools {

void run_eval_grid(const GridEvalOptions& o) {
  const products::Grid2d grid = products::read_grid(o.grid);
  const std::vector<eval::Triangle> scene = scene_triangles(o.scene);
  const Eigen::Isometry3d map_from_world = world_from_map(o.ref, o.est).inverse();
  const slam::Trajectory ref = timed_trajectory(o.ref);
  const slam::Trajectory est = timed_trajectory(o.est);
  std::vector<Eigen::Vector3d> path;  // the truth over the estimate's time span
  for (std::size_t i = 0; i < ref.size(); ++i)
    if (ref.stamps[i] >= est.stamps.front() && ref.stamps[i] <= est.stamps.back())
      path.push_back(ref.poses[i].translation());
  if (path.empty()) throw InputError(o.ref, "", fmt::format("no pose within {}'s time span", o.est));
  eval::GridTruthOptions options;
  options.max_range_m = o.max_range;
  options.floor_z = o.floor_z;
  const eval::GridTruthScore s = score_grid(
      {grid.resolution_m, grid.origin_x, grid.origin_y, grid.width, grid.height, grid.cells}, scene, map_from_world,
      path, options);
  if (!o.diff_png.empty()) {
    // Row 0 of the lattice is at the grid's origin_y: drawn at the bottom, north up.
    products::RasterImage image(s.lattice_width, s.lattice_height, {0, 0, 0});
    for (int r = 0; r < s.lattice_height; ++r)
      for (int c = 0; c < s.lattice_width; ++c) {
        using A = eval::CellAgreement;
        const A a = s.cells[static_cast<std::size_t>(r) * s.lattice_width + c];
        const products::Rgb colour = a == A::free_both              ? products::Rgb{40, 150, 60}
                                     : a == A::free_truth_unknown   ? products::Rgb{220, 40, 40}
                                     : a == A::occupied_grid_only  ? products::Rgb{255, 150, 0}
                                     : a == A::occupied_both        ? products::Rgb{255, 255, 255}
                                     : a == A::occupied_truth_only  ? products::Rgb{230, 0, 230}
                                     : a == A::free_grid_only       ? products::Rgb{60, 110, 255}
                                     : a == A::unseen_both          ? products::Rgb{60, 60, 60}
                                                                    : products::Rgb{0, 0, 0};
        image.set(c, s.lattice_height - 1 - r, colour);
      }
    image.write_png(o.diff_png);
  }
  if (o.json) {
    const nlohmann::json j = {{"iou_free", s.iou_free},
                              {"iou_occupied", s.iou_occupied},
                              {"iou_occupied_within_1_cell", s.iou_occupied_within_1_cell},
                              {"iou_known", s.iou_known},
                              {"truth_free", s.truth_free},
                              {"truth_occupied", s.truth_occupied},
                              {"grid_free", s.grid_free},
                              {"grid_occupied", s.grid_occupied},
                              {"cell_m", options.cell_m},
                              {"max_range_m", options.max_range_m}};
    fmt::print("{}\n", j.dump(2));
    return;
  }
  fmt::print("grid              {} x {} cells of {} m; truth on a {} m lattice, within {} m of the path\n", grid.width,
             grid.height, grid.resolution_m, options.cell_m, options.max_range_m);
  fmt::print("cells             truth free {}, occupied {}; grid free {}, occupied {}\n", s.truth_free,
             s.truth_occupied, s.grid_free, s.grid_occupied);
  fmt::print("iou free          {:.4f}\n", s.iou_free);
  fmt::print("iou occupied      {:.4f}\n", s.iou_occupied);
  fmt::print("iou occupied ±1   {:.4f}\n", s.iou_occupied_within_1_cell);
  fmt::print("iou known         {:.4f}\n", s.iou_known);
}

}  // namespace adit::tools
