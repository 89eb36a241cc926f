// adit eval traj|endpoint|targets|map: accuracy numbers from trajectories,
// total-station targets and scene meshes (docs/EVALUATION.md defines every metric).

#include <memory>

#include "adit/common/error.hpp"
#include "commands.hpp"
#include "eval_commands.hpp"

namespace adit::tools {
namespace {

const std::vector<std::string> kFormats{"auto", "tum", "kitti", "euroc"};

void add_traj(CLI::App& eval, int& status) {
  auto* cmd = eval.add_subcommand("traj", "Compare an estimated trajectory with a reference: APE, RPE, KITTI drift");
  auto o = std::make_shared<TrajEvalOptions>();
  cmd->add_option("--ref", o->ref, "Reference (ground-truth) trajectory file")->required()->check(CLI::ExistingFile);
  cmd->add_option("--est", o->est, "Estimated trajectory file")->required()->check(CLI::ExistingFile);
  cmd->add_option("--ref-format", o->ref_format, "Reference format: auto, tum, kitti, euroc (default auto)")
      ->check(CLI::IsMember(kFormats));
  cmd->add_option("--est-format", o->est_format, "Estimate format: auto, tum, kitti, euroc (default auto)")
      ->check(CLI::IsMember(kFormats));
  cmd->add_option("--ref-times", o->ref_times, "Times file (s, one per line) for a KITTI reference")
      ->check(CLI::ExistingFile);
  cmd->add_option("--est-times", o->est_times, "Times file (s, one per line) for a KITTI estimate")
      ->check(CLI::ExistingFile);
  cmd->add_option("--max-diff", o->max_diff, "Largest time difference (s) of an associated pair (default 0.01)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--offset", o->offset, "Seconds added to the estimate's stamps before association (default 0)");
  cmd->add_option("--align", o->align, "Alignment of the estimate: none, origin, se3, sim3 (default se3)")
      ->check(CLI::IsMember({"none", "origin", "se3", "sim3"}));
  cmd->add_option("--delta", o->delta, "RPE step between the poses of a pair (default 1)")->check(CLI::PositiveNumber);
  cmd->add_option("--delta-unit", o->delta_unit, "RPE step unit: frames, m (path length) or s (default frames)")
      ->check(CLI::IsMember({"frames", "m", "s"}));
  cmd->add_flag("--all-pairs", o->all_pairs, "RPE from every pose instead of consecutive pairs");
  cmd->add_option("--pairs-on", o->pairs_on,
                  "Trajectory whose path length and stamps choose the RPE pairs: est (as evo) or ref (default est)")
      ->check(CLI::IsMember({"est", "ref"}));
  cmd->add_flag("--json", o->json, "Print JSON instead of tables");
  cmd->add_option("--svg", o->svg_prefix,
                  "Write plots PREFIX-plan.svg (trajectories overlaid) and PREFIX-ape.svg (error along the path)");
  cmd->add_option("--save-aligned", o->save_aligned, "Write the associated, aligned estimate as a TUM file");
  cmd->callback([o, &status] {
    run_eval_traj(*o);
    status = kExitOk;
  });
}

void add_endpoint(CLI::App& eval, int& status) {
  auto* cmd = eval.add_subcommand(
      "endpoint", "End-to-end drift of a run that returns near its start, against a total-station delta");
  auto o = std::make_shared<EndpointEvalOptions>();
  cmd->add_option("--est", o->est, "Estimated trajectory file")->required()->check(CLI::ExistingFile);
  cmd->add_option("--format", o->format, "Trajectory format: auto, tum, kitti, euroc (default auto)")
      ->check(CLI::IsMember(kFormats));
  cmd->add_option("--times", o->times, "Times file for a KITTI trajectory")->check(CLI::ExistingFile);
  cmd->add_option("--true-delta", o->true_delta,
                  "Start-to-end difference measured by total station, DX,DY,DZ in metres (trajectory frame)")
      ->required();
  cmd->add_flag("--json", o->json, "Print JSON instead of a table");
  cmd->callback([o, &status] {
    run_eval_endpoint(*o);
    status = kExitOk;
  });
}

void add_targets(CLI::App& eval, int& status) {
  auto* cmd = eval.add_subcommand("targets", "Check map targets against total-station targets (CSV id,x,y,z)");
  auto o = std::make_shared<TargetsEvalOptions>();
  cmd->add_option("--truth", o->truth, "Targets surveyed by total station: CSV id,x,y,z in metres")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--map", o->map, "The same targets picked in the map: CSV id,x,y,z in metres")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--control", o->control, "Comma-separated ids the fit uses (at least 3; default all)");
  cmd->add_flag("--scale", o->scale, "Fit a similarity (with scale) instead of a rigid transform");
  cmd->add_flag("--json", o->json, "Print JSON instead of tables");
  cmd->add_option("--svg", o->svg, "Write a bar chart of the target errors to this SVG file");
  cmd->callback([o, &status] {
    run_eval_targets(*o);
    status = kExitOk;
  });
}

void add_map(CLI::App& eval, int& status) {
  auto* cmd = eval.add_subcommand("map", "Distance of every map point to the true scene surfaces (a triangle mesh)");
  auto o = std::make_shared<MapEvalOptions>();
  cmd->add_option("--map", o->map, "Map file: .ply, .pcd or .las (as aditd exports them)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--scene", o->scene, "True scene: triangle mesh PLY (adit sim's scene.ply)")
      ->required()
      ->check(CLI::ExistingFile);
  auto* ref = cmd->add_option("--ref", o->ref, "Reference body trajectory (truth_body.tum) to place the map in the scene")
                  ->check(CLI::ExistingFile);
  auto* est = cmd->add_option("--est", o->est, "The map's own trajectory (trajectory.tum), placed by ref(t0) est(t0)^-1")
                  ->check(CLI::ExistingFile);
  ref->needs(est);
  est->needs(ref);
  cmd->add_option("--align", o->align,
                  "Placement by the trajectories: origin (ref(t0) est(t0)^-1), heading (the same turned about the "
                  "vertical only: the map keeps its own tilt) or se3 (the rigid fit of all poses, as to control "
                  "points; use the map's poses, map_trajectory.tum) (default origin)")
      ->check(CLI::IsMember({"origin", "heading", "se3"}))
      ->needs(ref);
  cmd->add_option("--within", o->within, "Distance (m) a point must be within to count as accurate (default 0.05)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--cap", o->cap, "Distances beyond this (m) are counted as beyond, not computed (default 1)")
      ->check(CLI::Range(1e-3, 100.0));
  cmd->add_flag("--json", o->json, "Print JSON instead of a table");
  cmd->callback([o, &status] {
    run_eval_map(*o);
    status = kExitOk;
  });
}

void add_grid(CLI::App& eval, int& status) {
  auto* cmd = eval.add_subcommand("grid", "2D occupancy grid (map_server YAML + PGM) against the true scene: IoU");
  auto o = std::make_shared<GridEvalOptions>();
  cmd->add_option("--grid", o->grid, "The grid's YAML (adit products' grid.yaml)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--scene", o->scene, "True scene: triangle mesh PLY (adit sim's scene.ply)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--ref", o->ref, "Reference body trajectory (truth_body.tum)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--est", o->est, "The map's trajectory (map_trajectory.tum), placed by ref(t0) est(t0)^-1")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--max-range", o->max_range, "Cells farther than this (m) from the path are not scored (default 20)")
      ->check(CLI::Range(1.0, 200.0));
  cmd->add_option("--floor-z", o->floor_z, "The scene's floor height in the world (default 0)");
  cmd->add_option("--diff-png", o->diff_png,
                  "Write a picture of the agreement: green free in both, red free but unknown in the grid, orange "
                  "occupied in the grid with no true wall within a cell, white walls in both, magenta true walls the grid lacks, blue free in the "
                  "grid only, dark grey seen by neither");
  cmd->add_flag("--json", o->json, "Print JSON instead of a table");
  cmd->callback([o, &status] {
    run_eval_grid(*o);
    status = kExitOk;
  });
}

void add_sections(CLI::App& eval, int& status) {
  auto* cmd = eval.add_subcommand("sections", "Cross-section widths and heights (adit products) against the true scene");
  auto o = std::make_shared<SectionsEvalOptions>();
  cmd->add_option("--sections", o->sections, "sections.csv from adit products")->required()->check(CLI::ExistingFile);
  cmd->add_option("--scene", o->scene, "True scene: triangle mesh PLY (adit sim's scene.ply)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--ref", o->ref, "Reference body trajectory (truth_body.tum)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--est", o->est, "The map's trajectory (map_trajectory.tum)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--width-at", o->width_at, "Height above the floor the widths were measured at (m, default 1.5)");
  cmd->add_flag("--json", o->json, "Print JSON instead of a table");
  cmd->callback([o, &status] {
    run_eval_sections(*o);
    status = kExitOk;
  });
}

void add_moving(CLI::App& eval, int& status) {
  auto* cmd = eval.add_subcommand("moving", "Moving objects removed by adit products against the simulator's people");
  auto o = std::make_shared<MovingEvalOptions>();
  cmd->add_option("--kept", o->kept, "The map without them (adit products' map_static.las/.ply/.pcd)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--removed", o->removed, "The removed points (adit products' moving_points.ply)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--people", o->people, "The people's tracks (adit sim's truth_people.csv)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--ref", o->ref, "Reference body trajectory (truth_body.tum)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--est", o->est, "The map's trajectory (map_trajectory.tum)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--margin", o->margin, "Added to the people's radius and height (m, default 0.1)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_flag("--json", o->json, "Print JSON instead of text");
  cmd->callback([o, &status] {
    run_eval_moving(*o);
    status = kExitOk;
  });
}

}  // namespace

void add_loops(CLI::App& eval, int& status) {
  auto* cmd = eval.add_subcommand("loops", "Loop detection of an aditd session against the simulator's truth: precision, recall, error");
  auto o = std::make_shared<LoopsEvalOptions>();
  cmd->add_option("--session", o->session, "aditd's session folder (summary.json, keyframes.tum)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--truth", o->truth, "The simulator's truth_body.tum")->required()->check(CLI::ExistingFile);
  cmd->add_option("--revisit", o->judge.revisit_m, "True revisit: keyframes' true positions within this (m, default 3)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--min-path", o->judge.min_path_m, "... and at least this far apart along the true path (m, default 30)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--false-beyond", o->judge.false_beyond_m, "An accepted loop whose keyframes lie farther apart is false (m, default 10)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--max-error", o->judge.max_error_m, "... or whose measurement is off the truth by more (m, default 0.3)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--max-error-deg", o->judge.max_error_deg, "... or by more (degrees, default 1)")->check(CLI::PositiveNumber);
  cmd->add_option("--window", o->judge.window, "Recall: a true loop within this many keyframes of a revisit (default 5)");
  cmd->add_flag("--json", o->json, "Print JSON instead of a table");
  cmd->callback([o, &status] {
    run_eval_loops(*o);
    status = kExitOk;
  });
}

void register_eval_commands(CLI::App& app, int& status) {
  auto* eval = app.add_subcommand("eval", "Accuracy evaluation: trajectories, end-to-end drift, survey targets, map against scene, loops");
  eval->require_subcommand(1);
  add_traj(*eval, status);
  add_endpoint(*eval, status);
  add_targets(*eval, status);
  add_map(*eval, status);
  add_grid(*eval, status);
  add_moving(*eval, status);
  add_sections(*eval, status);
  add_loops(*eval, status);
}

}  // namespace adit::tools
