// adit products SESSION_DIR: the products of a finished session (3D
// occupancy, 2D grid) written from its folder, with their storage figures
// (docs/PRODUCTS.md).

#include <memory>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/products/session_products.hpp"
#include "commands.hpp"

namespace adit::tools {
namespace {

struct ProductsCommand {
  std::string session;
  std::string out;
  products::ProductsOptions options;
};

std::string kib(std::uintmax_t bytes) { return fmt::format("{:.1f} kB", static_cast<double>(bytes) / 1000.0); }

void run_products(const ProductsCommand& c) {
  const products::ProductsReport r = products::write_session_products(c.session, c.options, c.out);
  fmt::print("products of {} in {}\n", c.session, r.out_dir.string());
  if (r.thin_voxel_m > 0.0)
    fmt::print("read              {} map points, {} more than one in a {} m voxel left out\n", r.read_points, r.thinned,
               r.thin_voxel_m);
  else
    fmt::print("read              {} map points, all kept\n", r.read_points);
  if (r.moving_skipped.empty())
    fmt::print("moving objects    {} map points removed ({} suspects; seen through by later or earlier scans, {} "
               "scans of the recording; {:.2f} s CPU); the rest in map_static, the removed in moving_points.ply\n",
               r.moving_removed, r.moving_suspects, r.moving_scans, r.moving_cpu_s);
  else
    fmt::print("moving objects    not removed: {}\n", r.moving_skipped);
  fmt::print("points            {} ({} ground, {} outliers removed, {} without a line of sight to the path)\n", r.points,
             r.ground_points, r.outliers_removed, r.without_ray);
  fmt::print("octree            {} leaves at {} m\n", r.leaves, c.options.occupancy.resolution_m);
  fmt::print("grid              {} occupied, {} free ({} by the line-of-sight fill), {} unknown cells at {} m\n",
             r.grid_occupied, r.grid_free, r.grid_filled, r.grid_unknown, c.options.grid_resolution_m);
  fmt::print("storage           points {} -> 3D {} (.bt){} -> 2D {} (PGM + YAML)\n", kib(r.points_bytes),
             kib(r.bt_bytes), r.ot_bytes > 0 ? fmt::format(", {} (.ot)", kib(r.ot_bytes)) : "", kib(r.grid_bytes));
  fmt::print("pictures          top_view.png ({}), {} cross-sections ({} measured, {} moved to where the walls run on, "
             "{} without a width: the walls break) every {} m in sections/\n",
             kib(r.top_view_bytes), r.sections, r.sections_measured, r.sections_moved, r.sections_walls_broken,
             c.options.sections.interval_m);
  fmt::print("cpu               {:.2f} s\n", r.cpu_s);
  for (const auto& [step, s] : r.cpu_by_step) fmt::print("  {:<24}{:.2f} s\n", step, s);
}

}  // namespace

void register_products_commands(CLI::App& app, int& status) {
  auto* cmd = app.add_subcommand("products", "A finished session's products: 3D occupancy (.bt), 2D grid (PGM + YAML)");
  auto c = std::make_shared<ProductsCommand>();
  products::ProductsOptions& o = c->options;
  cmd->add_option("session", c->session, "The session folder (map.ply, map_trajectory.tum, config.yaml)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--out", c->out, "Where to write (default SESSION/products)");
  cmd->add_option("--thin-voxel", o.thin_voxel_m,
                  "Keep one map point per voxel of this edge first (m; default: the session's map.voxel_m; 0: every point)");
  cmd->add_option("--grid-resolution", o.grid_resolution_m, "2D grid cell (m), 0.01 .. 1 (default 0.05)");
  cmd->add_option("--octree-resolution", o.occupancy.resolution_m, "3D voxel (m), 0.01 .. 1 (default 0.1)");
  cmd->add_option("--band", o.band_low_m, "Lowest height above the ground that blocks (m, default 0.15)");
  cmd->add_option("--band-high", o.band_high_m, "Highest height above the ground that blocks (m, default 2.0)");
  cmd->add_option("--sor-k", o.outliers.k, "Statistical outlier removal: neighbours (default 15)");
  cmd->add_option("--sor-stddev", o.outliers.stddev_mult, "Statistical outlier removal: stddev multiple (default 1.0)");
  cmd->add_option("--ground-distance", o.ground.distance_m, "Ground: distance to the patch plane (m, default 0.12)");
  cmd->add_option("--section-interval", o.sections.interval_m, "Cross-sections every this many m of path (default 10)");
  cmd->add_option("--section-width-at", o.sections.width_at_m, "Widths measured this high above the floor (m, default 1.5)");
  cmd->add_option("--section-max-shift", o.sections.max_shift_m,
                  "A station moves along the path up to this far to where both walls run on (m, default 2; 0: stations at "
                  "their nominal chainage)");
  cmd->add_option("--ray-candidates", o.rays.candidates, "Path positions tried for each point's line of sight (default 12)");
  cmd->add_flag("!--keep-moving", o.moving.enabled,
                "Keep the map points of moving objects (people, vehicles) that the raw recording's scans saw through");
  cmd->add_option("--moving-min-through", o.moving.min_through,
                  "Moving objects: scans that must see through a point, at least (default 2)");
  cmd->add_option("--moving-margin", o.moving.margin_m,
                  "Moving objects: how far past a point the returns around it must go (m, default 0.3)");
  cmd->add_option("--moving-max-range", o.moving.max_range_m,
                  "Moving objects: map points farther than this from the sensor are not tested in a scan (m, default 25)");
  cmd->add_option("--moving-coarse-step", o.moving.coarse_step,
                  "Moving objects: suspects from every n-th scan first, then judged on every --moving-scan-step-th "
                  "(0: one pass over all points; default 16)");
  cmd->add_option("--moving-coarse-retire", o.moving.coarse_retire_after_looks,
                  "Moving objects: in the coarse pass, a point looked at (all four returns there) in this many scans over "
                  "--moving-coarse-retire-scans or more and never seen through is tested no more (0: never retired; default 8)")
      ->check(CLI::Range(0, 65535));
  cmd->add_option("--moving-coarse-retire-scans", o.moving.coarse_retire_after_scans,
                  "Moving objects: the coarse scans from a point's first look before it may retire (default 40)")
      ->check(CLI::Range(0, 1000000));
  cmd->add_flag("--moving-nearest-return-only", o.moving.nearest_return_only,
                "Moving objects: compare with the one nearest return, not the four around (for measurements)");
  cmd->add_option("--moving-through-ratio", o.moving.through_ratio,
                  "Moving objects: scans seeing through a point must be at least this many times those seeing it "
                  "(default 1)");
  cmd->add_option("--moving-scan-step", o.moving.scan_step, "Moving objects: use every n-th scan (default 1)");
  cmd->add_flag("!--no-fill", o.line_of_sight_fill, "No 2D line-of-sight fill of the grid's free space");
  cmd->add_option("--fill-step", o.fill_step_m, "Line-of-sight fill: a viewpoint every this many m of path (default 0.25: every one)")
      ->check(CLI::Range(0.05, 100.0));
  cmd->add_flag("--ot", o.write_ot, "Also write the full-probability octree (.ot)");
  cmd->callback([c, &status] {
    run_products(*c);
    status = kExitOk;
  });
}

}  // namespace adit::tools
