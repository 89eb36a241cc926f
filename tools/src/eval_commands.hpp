#pragma once
// The `adit eval` subcommands: their options and what runs them. Each
// runner prints a table (or JSON with --json) on stdout, writes the plots it
// was asked for, and throws adit::InputError on bad input (exit status 2).

#include <string>

#include <nlohmann/json.hpp>

#include <vector>

#include <Eigen/Geometry>

#include "adit/eval/loop_truth.hpp"
#include "adit/eval/mesh_distance.hpp"
#include "adit/eval/stats.hpp"
#include "adit/slam/trajectory.hpp"

namespace adit::tools {

struct TrajEvalOptions {
  std::string ref, est;
  std::string ref_format = "auto", est_format = "auto";
  std::string ref_times, est_times;
  double max_diff = 0.01;
  double offset = 0.0;
  std::string align = "se3";
  double delta = 1.0;
  std::string delta_unit = "frames";
  bool all_pairs = false;
  std::string pairs_on = "est";  // whose path/stamps choose the RPE pairs
  bool json = false;
  std::string svg_prefix;
  std::string save_aligned;
};

struct EndpointEvalOptions {
  std::string est;
  std::string format = "auto";
  std::string times;
  std::string true_delta;
  bool json = false;
};

struct TargetsEvalOptions {
  std::string truth, map;
  std::string control;
  bool scale = false;
  bool json = false;
  std::string svg;
};

struct MapEvalOptions {
  std::string map, scene;
  std::string ref, est;  // both or neither: place the map by ref(t0) · est(t0)⁻¹ (origin)
  std::string align = "origin";  // "heading": turned about the vertical only; "se3": by the rigid fit of est's positions to ref's
  double within = 0.05;  // m
  double cap = 1.0;      // m: farther distances are counted, not computed
  bool json = false;
};

void run_eval_traj(const TrajEvalOptions& options);
void run_eval_map(const MapEvalOptions& options);
void run_eval_endpoint(const EndpointEvalOptions& options);
void run_eval_targets(const TargetsEvalOptions& options);

struct GridEvalOptions {
  std::string grid, scene;  // grid.yaml (map_server), scene.ply
  std::string ref, est;     // truth_body.tum and the map's trajectory: place the grid by ref(t0) · est(t0)⁻¹
  double max_range = 20.0;  // m: cells farther from the path are not scored
  double floor_z = 0.0;     // the scene's floor height (world)
  bool json = false;
  std::string diff_png;     // a picture of where the grid and the truth agree and differ
};

void run_eval_grid(const GridEvalOptions& options);

struct SectionsEvalOptions {
  std::string sections, scene;  // adit products' sections.csv, scene.ply
  std::string ref, est;         // truth_body.tum and the map's trajectory
  double width_at = 1.5;        // m above the floor, as the sections were measured
  bool json = false;
};

void run_eval_sections(const SectionsEvalOptions& options);

struct MovingEvalOptions {
  std::string kept, removed;  // adit products' map_static.* and moving_points.ply
  std::string people;         // adit sim's truth_people.csv
  std::string ref, est;       // truth_body.tum and the map's trajectory
  double margin = 0.10;       // m added to the people's cylinders
  bool json = false;
};

void run_eval_moving(const MovingEvalOptions& options);

struct LoopsEvalOptions {
  std::string session;  // aditd's session folder: summary.json ("loops"."edges") and keyframes.tum
  std::string truth;    // adit sim's truth_body.tum
  eval::LoopTruthConfig judge;  // what counts as a revisit, a false loop, a recalled one
  bool json = false;
};

void run_eval_loops(const LoopsEvalOptions& options);

// Shared by the runners.
// The triangles of a scene mesh PLY; throws InputError when it has none.
std::vector<eval::Triangle> scene_triangles(const std::string& file);
// A time-stamped trajectory in any format eval reads (detected).
slam::Trajectory timed_trajectory(const std::string& file);
// Where the map frame lies in the world: ref(t0) · est(t0)⁻¹ at the estimate's first stamp t0.
Eigen::Isometry3d world_from_map(const std::string& ref_file, const std::string& est_file);
// Where the map frame lies in the world by a rigid fit of the estimate's
// positions to the reference's (Umeyama); `poses`: how many were matched.
Eigen::Isometry3d world_from_map_fitted(const std::string& ref_file, const std::string& est_file, std::size_t& poses);
nlohmann::json stats_json(const eval::Stats& stats);
std::string stats_row(const std::string& name, const eval::Stats& stats);
std::string stats_header();

}  // namespace adit::tools
