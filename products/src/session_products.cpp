#include "adit/products/session_products.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/common/clock.hpp"
#include "adit/common/error.hpp"
#include "adit/products/grid_io.hpp"
#include "adit/products/grid_projection.hpp"
#include "adit/products/session_map.hpp"
#include "adit/protocol/map_export.hpp"
#include "adit/protocol/map_import.hpp"

namespace adit::products {
namespace {

double thread_cpu_s() { return 1e-9 * static_cast<double>(thread_cpu_ns()); }

nlohmann::json report_json(const ProductsReport& r, const ProductsOptions& o) {
  nlohmann::json cpu_by_step = nlohmann::json::object();
  for (const auto& [step, s] : r.cpu_by_step) cpu_by_step[step] = s;
  nlohmann::json files = nlohmann::json::array();
  if (!r.map_static_file.empty()) files.insert(files.end(), {r.map_static_file, "moving_points.ply"});
  files.push_back("occupancy.bt");
  if (o.write_ot) files.push_back("occupancy.ot");
  files.insert(files.end(), {"grid.pgm", "grid.yaml", "top_view.png", "sections/"});
  if (r.targets_note.empty()) files.push_back("targets.csv");
  return {{"read_points", r.read_points},
          {"thinning", {{"voxel_m", r.thin_voxel_m}, {"dropped", r.thinned}}},
          {"points", r.points},
          {"moving_objects", {{"enabled", o.moving.enabled}, {"removed", r.moving_removed},
                              {"candidates", r.moving_candidates}, {"suspects", r.moving_suspects}, {"scans_used", r.moving_scans},
                              {"skipped_because", r.moving_skipped}, {"cpu_s", r.moving_cpu_s}, {"map_static_bytes", r.map_static_bytes}}},
          {"points_without_ray", r.without_ray},
          {"ground_points", r.ground_points},
          {"outliers_removed", r.outliers_removed},
          {"octree_leaves", r.leaves},
          {"octree_resolution_m", o.occupancy.resolution_m},
          {"grid_resolution_m", o.grid_resolution_m},
          {"grid_cells", {{"occupied", r.grid_occupied}, {"free", r.grid_free}, {"unknown", r.grid_unknown},
                          {"free_by_line_of_sight_fill", r.grid_filled}}},
          {"points_file", r.points_file},
          {"bytes", {{"points", r.points_bytes}, {"octree_bt", r.bt_bytes}, {"octree_ot", r.ot_bytes}, {"grid", r.grid_bytes}}},
          {"top_view_bytes", r.top_view_bytes},
          {"sections", {{"count", r.sections}, {"measured", r.sections_measured}, {"interval_m", o.sections.interval_m},
                        {"width_at_m", o.sections.width_at_m}, {"moved", r.sections_moved},
                        {"walls_broken", r.sections_walls_broken}, {"max_shift_m", o.sections.max_shift_m}}},
          {"targets", {{"found", r.targets}, {"note", r.targets_note}}},
          {"files", files},
          {"cpu_s", r.cpu_s},
          {"cpu_by_step_s", cpu_by_step}};
}

// summary.json gains "products"; written beside and renamed, so a reader
// never sees half a file.
void add_to_summary(const std::filesystem::path& summary, const nlohmann::json& products) {
  if (!std::filesystem::exists(summary)) return;
  nlohmann::json s;
  {
    std::ifstream in(summary);
    s = nlohmann::json::parse(in, nullptr, false);
  }
  if (s.is_discarded() || !s.is_object()) throw InputError(summary.string(), "", "is not a JSON object");
  s["products"] = products;
  std::filesystem::path tmp = summary;
  tmp += ".tmp";
  {
    std::ofstream out(tmp);
    out << s.dump(2) << "\n";
    if (!out) throw InputError(tmp.string(), "", "write failed");
  }
  std::filesystem::rename(tmp, summary);
}


}  // namespace

void check_options(const ProductsOptions& o) {
  const auto require = [](bool ok, const char* key, const std::string& what) {
    if (!ok) throw InputError("options", key, what);
  };
  require(o.grid_resolution_m >= 0.01 - 1e-12 && o.grid_resolution_m <= 1.0, "grid-resolution",
          fmt::format("{} m is outside 0.01 .. 1 m", o.grid_resolution_m));
  require(o.occupancy.resolution_m >= 0.01 - 1e-12 && o.occupancy.resolution_m <= 1.0, "octree-resolution",
          fmt::format("{} m is outside 0.01 .. 1 m", o.occupancy.resolution_m));
  require(!std::isnan(o.thin_voxel_m) && o.thin_voxel_m <= 1.0, "thin-voxel",
          fmt::format("{} m is above 1 m (0: every point kept)", o.thin_voxel_m));
  require(o.band_low_m < o.band_high_m, "band", "the band's low height must be below its high one");
  require(o.outliers.k >= 1 && o.outliers.stddev_mult > 0.0, "sor", "k >= 1 and a positive stddev multiple");
  require(o.ground.patch_m > 0.0 && o.ground.distance_m > 0.0, "ground", "patch and distance must be positive");
  require(o.sections.interval_m > 0.0, "section-interval", "must be positive");
  require(o.sections.max_shift_m >= 0.0 && o.sections.max_shift_m < o.sections.interval_m / 2, "section-max-shift",
          "from 0 to less than half the section interval");
  require(o.moving.margin_m > 0.0 && o.moving.margin_fraction >= 0.0 && o.moving.seen_tolerance_m > 0.0 &&
              o.moving.min_range_m >= 0.0 && o.moving.max_range_m > o.moving.min_range_m,
          "moving", "margins and tolerance positive, max range above min range");
  require(o.moving.min_through >= 1 && o.moving.scan_step >= 1, "moving-min-through",
          "at least one scan seeing through, a scan step of at least 1");
  require(o.moving.through_ratio >= 0.0 && o.moving.coarse_step >= 0, "moving-through-ratio",
          "the ratio and the coarse step must not be negative");
}

ProductsReport write_session_products(const std::filesystem::path& session_dir, const ProductsOptions& options,
                                      const std::filesystem::path& out_dir) {
  check_options(options);
  const auto check_cancel = [&options] {
    if (options.cancel != nullptr && options.cancel->load(std::memory_order_relaxed)) throw Cancelled();
  };
  const double cpu0 = thread_cpu_s();
  ProductsReport r;
  // Each step's CPU time, from the end of the one before.
  double lap0 = cpu0;
  const auto lap = [&r, &lap0](const char* step) {
    const double now = thread_cpu_s();
    r.cpu_by_step.emplace_back(step, now - lap0);
    lap0 = now;
  };
  r.out_dir = out_dir.empty() ? session_dir / "products" : out_dir;
  SessionInputs inputs = read_session_inputs(session_dir, options.thin_voxel_m);
  const std::filesystem::path map_file = map_file_of(session_dir);
  r.points_file = map_file.filename().string();
  r.points_bytes = std::filesystem::file_size(map_file);
  std::filesystem::create_directories(r.out_dir);
  r.read_points = inputs.read_points;
  r.thin_voxel_m = inputs.thin_voxel_m;
  r.thinned = inputs.thinned;
  lap("read_map");  // thinned as read
  check_cancel();
  {
    const double moving0 = thread_cpu_s();
    const MovingObjectsReport moving = remove_moving_objects(session_dir, inputs, {}, options.moving);
    r.moving_cpu_s = thread_cpu_s() - moving0;
    r.moving_removed = moving.removed;
    r.moving_candidates = moving.candidates;
    r.moving_suspects = moving.suspects;
    r.moving_scans = moving.scans_used;
    r.moving_skipped = moving.skipped_because;
    if (moving.ran) {
      const std::filesystem::path static_file = r.out_dir / ("map_static" + map_file.extension().string());
      protocol::write_map(static_file, protocol::map_format_of(map_file), inputs.points);
      r.map_static_bytes = std::filesystem::file_size(static_file);
      r.map_static_file = static_file.filename().string();
      protocol::write_map(r.out_dir / "moving_points.ply", protocol::MapFormat::ply, moving.removed_points);
    }
  }
  lap("moving_objects");
  const SessionMap map = rays_from(inputs.points, inputs.body_poses, inputs.body_to_sensor, options.rays);
  std::vector<protocol::MapPoint>().swap(inputs.points);  // the steps below use `map`: 154 MB on the 30-minute drive
  r.without_ray = map.without_ray;
  r.points = map.points.size();
  lap("rays_to_path");
  check_cancel();

  const GroundSegmentation ground = segment_ground(map.points, options.ground);
  r.ground_points = ground.ground_points;
  lap("ground");
  check_cancel();
  std::vector<std::uint8_t> non_ground(map.points.size());
  for (std::size_t i = 0; i < non_ground.size(); ++i) non_ground[i] = ground.is_ground[i] ? 0 : 1;
  const std::vector<std::uint8_t> kept = statistical_inliers(map.points, non_ground, options.outliers);
  r.outliers_removed = static_cast<std::size_t>(std::count(non_ground.begin(), non_ground.end(), 1) -
                                                std::count(kept.begin(), kept.end(), 1));
  lap("outliers");

  // Rays in batches of one viewpoint (OctoMap counts a voxel once per batch).
  std::vector<std::size_t> order;
  order.reserve(map.points.size());
  for (std::size_t i = 0; i < map.points.size(); ++i)
    if (map.origin[i] >= 0) order.push_back(i);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return map.origin[a] < map.origin[b]; });
  Occupancy3d occupancy(options.occupancy);
  std::vector<Eigen::Vector3f> hits, passes;
  check_cancel();
  for (std::size_t begin = 0; begin < order.size();) {
    check_cancel();
    std::size_t end = begin;
    hits.clear();
    passes.clear();
    for (; end < order.size() && map.origin[order[end]] == map.origin[order[begin]]; ++end) {
      const std::size_t i = order[end];
      if (kept[i]) hits.push_back(map.points[i]);
      else if (ground.is_ground[i]) passes.push_back(map.points[i]);
      // an outlier casts no ray: its range is what is in doubt
    }
    occupancy.insert(map.viewpoints[static_cast<std::size_t>(map.origin[order[begin]])], hits, passes);
    begin = end;
  }
  lap("octree");
  Grid2d grid = project_to_grid(occupancy, map.points, kept, ground.is_ground, ground.model,
                                {options.grid_resolution_m, options.band_low_m, options.band_high_m});
  lap("grid");
  if (options.line_of_sight_fill)
    r.grid_filled = fill_line_of_sight(grid, map.viewpoints, options.fill_range_m, options.fill_step_m);
  lap("grid_fill");
  check_cancel();
  r.grid_occupied = grid.count(kOccupied);
  r.grid_free = grid.count(kFree);
  r.grid_unknown = grid.count(kUnknown);

  r.grid_bytes = write_grid(r.out_dir / "grid", grid);
  if (options.write_ot) r.ot_bytes = occupancy.write_ot(r.out_dir / "occupancy.ot");
  r.bt_bytes = occupancy.write_bt(r.out_dir / "occupancy.bt");
  r.leaves = occupancy.leaf_count();
  lap("write_grid_and_octree");
  // Targets by intensity (target_finder.hpp); a map without intensities has none to find.
  std::vector<Eigen::Vector3d> target_centres;
  if (std::any_of(map.intensities.begin(), map.intensities.end(), [](float i) { return i > 0.0F; })) {
    const std::vector<FoundTarget> found = find_targets(map.points, map.intensities, map.sensor_path, options.targets);
    write_targets_csv(r.out_dir / "targets.csv", found);
    for (const FoundTarget& t : found) target_centres.push_back(t.centre);
    r.targets = found.size();
  } else {
    r.targets_note = "the map has no intensities: targets cannot be found";
  }
  lap("targets");
  r.top_view_bytes = write_top_view(r.out_dir / "top_view.png", map.points, ground.model, map.sensor_path, target_centres,
                                    options.top_view)
                         .bytes;
  lap("top_view");
  const std::vector<CrossSection> sections = cut_sections(map.points, map.sensor_path, options.sections);
  std::filesystem::create_directories(r.out_dir / "sections");
  for (const CrossSection& c : sections) {
    write_section_svg(r.out_dir / "sections" / fmt::format("section_{:03d}.svg", c.id), c, options.sections);
    r.sections_measured += std::isfinite(c.width_m) && std::isfinite(c.height_m);
    r.sections_moved += c.shift_m != 0.0;
    r.sections_walls_broken += !c.walls_regular;
  }
  r.sections = sections.size();
  write_sections_csv(r.out_dir / "sections" / "sections.csv", sections);
  lap("sections");
  r.cpu_s = thread_cpu_s() - cpu0;
  const nlohmann::json json = report_json(r, options);
  {
    std::ofstream out(r.out_dir / "products.json");
    out << json.dump(2) << "\n";
    if (!out) throw InputError((r.out_dir / "products.json").string(), "", "write failed");
  }
  add_to_summary(session_dir / "summary.json", json);
  return r;
}

}  // namespace adit::products
