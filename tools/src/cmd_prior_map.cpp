// adit prior-map prepare: a prior map (BIM export, design model, earlier
// survey) read, downsampled, given normals and a plan view, and written as a
// folder aditd and the benchmarks load (docs/PRIOR-MAP.md).
// adit prior-map deviations: a session's map against the prior: the
// deviation cloud (PLY scalar field), the regions beyond a threshold, and,
// on a simulated session, how well they find the scene's real differences.

#include <cmath>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/common/error.hpp"
#include "adit/eval/trajectory_io.hpp"
#include "adit/protocol/map_export.hpp"
#include "adit/protocol/map_import.hpp"
#include "adit/protocol/scalar_field_ply.hpp"
#include "adit/slam/global_localisation.hpp"
#include "adit/slam/prior_deviations.hpp"
#include "adit/slam/prior_map_file.hpp"
#include "commands.hpp"
#include "prior_map_source.hpp"

namespace adit::tools {
namespace {

struct PrepareOptions {
  std::string in;
  std::string out;
  protocol::PriorInputOptions input;
  std::vector<double> offset;
  std::string up = "z";
};

int prepare(const PrepareOptions& o) {
  protocol::PriorInputOptions input = o.input;
  if (!o.offset.empty()) input.offset = {o.offset[0], o.offset[1], o.offset[2]};
  input.y_up = o.up == "y";
  const LoadedPrior prior = load_prior(o.in, input);
  const std::filesystem::path dir(o.out);
  slam::write_prior_map(dir, prior.map);
  // The prepared points for a viewer (CloudCompare, adit eval map), intensity = 100 |n_z|.
  std::vector<protocol::MapPoint> points(prior.map.points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    points[i].x = prior.map.points[i].x();
    points[i].y = prior.map.points[i].y();
    points[i].z = prior.map.points[i].z();
    points[i].intensity = 100.0F * std::abs(prior.map.normals[i].z());
  }
  protocol::write_map(dir / "points.ply", protocol::MapFormat::ply, points);
  const slam::PlanGrid& plan = prior.map.plan;
  fmt::print("prior map: {} -> {}\n", o.in, (dir / slam::kPriorMapFile).string());
  fmt::print("points: {} read, {} kept at {:.2f} m ({} on vertical surfaces, {} on floors and ceilings)\n",
             prior.input_points, prior.map.points.size(), prior.map.point_spacing_m, prior.map.vertical_points,
             prior.map.horizontal_points);
  fmt::print("plan: {} x {} cells of {:.2f} m from ({:.2f}, {:.2f})\n", plan.width, plan.height, plan.cell_m,
             plan.origin.x(), plan.origin.y());
  fmt::print("memory: {:.1f} MB; prepared in {:.1f} s\n", 1e-6 * static_cast<double>(prior_map_bytes(prior.map)),
             prior.prepare_s);
  return kExitOk;
}

struct DeviationOptions {
  std::string session;
  std::string prior;
  std::string out;
  std::string truth_scene;
  float threshold_m = 0.05F;
  float smooth_m = 0.0F;  // measured: it costs recall more than it buys precision (docs/decisions)
  std::size_t min_region_points = 50;
  float region_share = slam::DeviationConfig{}.region_min_share;
  bool aligned = false;
  bool json = false;
};

std::vector<Eigen::Vector3f> to_points(const std::vector<std::array<float, 3>>& in) {
  std::vector<Eigen::Vector3f> out(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) out[i] = Eigen::Vector3f(in[i][0], in[i][1], in[i][2]);
  return out;
}

// Truth on a simulated session: a map point lies on a real difference when
// the built scene's surface under it is more than the threshold from the
// design (furniture, the moved partition). Labels: 1 changed, 0 unchanged,
// -1 no scene surface within 0.15 m (noise, walkers).
std::vector<int> truth_labels(std::span<const Eigen::Vector3f> points, const std::string& scene,
                              const slam::PriorMap& prior, float threshold) {
  protocol::PriorInputOptions sampling;
  sampling.mesh_points_per_m2 = 400.0;
  const std::vector<Eigen::Vector3f> surface = to_points(protocol::read_prior_input(scene, sampling).points);
  const std::vector<Eigen::Vector3f> no_views;
  const std::vector<float> design = slam::signed_deviations(surface, no_views, prior);
  std::vector<Eigen::Vector3f> changed, unchanged;
  for (std::size_t i = 0; i < surface.size(); ++i) (std::abs(design[i]) > threshold ? changed : unchanged).push_back(surface[i]);
  slam::VoxelHashMap changed_index(0.15F, 2 * changed.size() / 4 + 1024), unchanged_index(0.15F, 2 * unchanged.size() / 4 + 1024);
  changed_index.add(changed);
  unchanged_index.add(unchanged);
  std::vector<int> labels(points.size(), -1);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const slam::MapNeighbor c = changed_index.nearest(points[i], 0.15F);
    const slam::MapNeighbor u = unchanged_index.nearest(points[i], 0.15F);
    if (c.found || u.found) labels[i] = (c.found && (!u.found || c.distance_sq < u.distance_sq)) ? 1 : 0;
  }
  return labels;
}

int deviations(const DeviationOptions& o) {
  const std::filesystem::path session(o.session);
  const std::vector<protocol::MapPoint> map = protocol::read_map(session / "map.ply");
  const slam::Trajectory trajectory = eval::read_tum(session / "trajectory.tum");
  if (map.empty() || trajectory.empty()) throw InputError(o.session, "", "empty map or trajectory");
  const LoadedPrior prior = load_prior(o.prior);
  const slam::VoxelHashMap index = slam::index_prior_map(prior.map);
  std::vector<Eigen::Vector3f> points(map.size());
  for (std::size_t i = 0; i < map.size(); ++i) points[i] = Eigen::Vector3d(map[i].x, map[i].y, map[i].z).cast<float>();
  // The map in the prior's frame: found by global localisation from the
  // map's start (a metre above the first pose: a sensor's place), unless it is there already.
  Eigen::Isometry3d prior_from_map = Eigen::Isometry3d::Identity();
  if (!o.aligned) {
    const Eigen::Vector3f origin = (trajectory.poses.front().translation() + Eigen::Vector3d(0, 0, 1.0)).cast<float>();
    std::vector<Eigen::Vector3f> cloud(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) cloud[i] = points[i] - origin;
    slam::LocalisationConfig config;
    config.search_range_m = 60.0F;
    config.max_search_points = 1500;
    const slam::LocalisationResult r = slam::localise(cloud, prior.map, index, std::nullopt, config);
    if (!r.success)
      throw InputError(o.session, "", "the map could not be placed in the prior's frame: " + r.failure +
                                          " (give --aligned if it is already there)");
    prior_from_map = r.pose * Eigen::Translation3d(-origin.cast<double>());
    if (!o.json) fmt::print("map placed in the prior: overlap {:.2f}, rival {:.2f}\n", r.overlap, r.rival_overlap);
  }
  const Eigen::Isometry3f t = prior_from_map.cast<float>();
  for (auto& p : points) p = t * p;
  std::vector<Eigen::Vector3f> views;
  for (const auto& pose : trajectory.poses) views.push_back((prior_from_map * pose).translation().cast<float>());
  slam::DeviationConfig config;
  config.threshold_m = o.threshold_m;
  config.min_region_points = o.min_region_points;
  config.region_min_share = o.region_share;
  const std::vector<float> raw = slam::signed_deviations(points, views, prior.map, config);
  const std::vector<float> dev = o.smooth_m > 0.0F ? slam::smooth_deviations(points, raw, o.smooth_m) : raw;
  std::vector<int> member(points.size());
  const std::vector<slam::DeviationRegion> regions = slam::deviation_regions(points, dev, config, member);

  const std::vector<int> truth =
      o.truth_scene.empty() ? std::vector<int>{} : truth_labels(points, o.truth_scene, prior.map, o.threshold_m);
  std::error_code ec;
  std::filesystem::create_directories(o.out, ec);
  const std::filesystem::path cloud_file = std::filesystem::path(o.out) / "deviations.ply";
  std::vector<std::array<float, 3>> xyz(points.size());
  std::vector<float> region_field(points.size());
  std::vector<float> truth_field(truth.size());  // with --truth-scene: each point's label, to see the errors
  for (std::size_t i = 0; i < points.size(); ++i) {
    xyz[i] = {points[i].x(), points[i].y(), points[i].z()};
    region_field[i] = static_cast<float>(member[i]);
    if (!truth.empty()) truth_field[i] = static_cast<float>(truth[i]);
  }
  std::vector<protocol::ScalarField> fields{protocol::ScalarField{"deviation", dev},
                                            protocol::ScalarField{"raw_deviation", raw},
                                            protocol::ScalarField{"region", region_field}};
  if (!truth.empty()) fields.push_back(protocol::ScalarField{"truth", truth_field});
  protocol::write_scalar_field_ply(cloud_file, xyz, fields);
  nlohmann::json j;
  j["map_points"] = points.size();
  j["threshold_m"] = o.threshold_m;
  std::size_t deviating = 0;
  for (const float d : dev) deviating += std::abs(d) > o.threshold_m ? 1 : 0;
  j["deviating_points"] = deviating;
  j["regions"] = nlohmann::json::array();
  for (std::size_t r = 0; r < regions.size(); ++r) {
    const auto& g = regions[r];
    const Eigen::Vector3f size = g.hi - g.lo;
    j["regions"].push_back({{"id", r}, {"points", g.points}, {"centroid_m", {g.centroid.x(), g.centroid.y(), g.centroid.z()}},
                            {"size_m", {size.x(), size.y(), size.z()}}, {"mean_deviation_m", g.mean_m},
                            {"max_abs_deviation_m", g.max_abs_m}});
  }
  if (!truth.empty()) {
    const auto score = [&](auto predicted) {
      std::size_t tp = 0, fp = 0, fn = 0;
      for (std::size_t i = 0; i < points.size(); ++i) {
        if (truth[i] < 0) continue;
        const bool p = predicted(i);
        tp += (p && truth[i] == 1) ? 1 : 0;
        fp += (p && truth[i] == 0) ? 1 : 0;
        fn += (!p && truth[i] == 1) ? 1 : 0;
      }
      return std::pair{tp + fp ? static_cast<double>(tp) / static_cast<double>(tp + fp) : 0.0,
                       tp + fn ? static_cast<double>(tp) / static_cast<double>(tp + fn) : 0.0};
    };
    const auto [p_point, r_point] = score([&](std::size_t i) { return std::abs(dev[i]) > o.threshold_m; });
    const auto [p_region, r_region] = score([&](std::size_t i) { return member[i] >= 0; });
    std::size_t changed = 0, labelled = 0;
    for (const int l : truth) {
      changed += l == 1 ? 1 : 0;
      labelled += l >= 0 ? 1 : 0;
    }
    j["truth"] = {{"scene", o.truth_scene}, {"labelled_points", labelled}, {"changed_points", changed},
                  {"precision_points", p_point}, {"recall_points", r_point},
                  {"precision_regions", p_region}, {"recall_regions", r_region}};
  }
  std::ofstream(std::filesystem::path(o.out) / "deviations.json") << j.dump(2) << "\n";
  if (o.json) {
    fmt::print("{}\n", j.dump(2));
    return kExitOk;
  }
  fmt::print("deviation cloud: {} ({} points, scalar fields 'deviation' (m, + in front of the design), 'raw_deviation', "
             "'region'{})\n",
             cloud_file.string(), points.size(), truth.empty() ? "" : " and 'truth' (1 a real difference, 0 none, -1 unknown)");
  fmt::print("{} points deviate by more than {:.3f} m; {} regions of at least {} points:\n", deviating, o.threshold_m,
             regions.size(), o.min_region_points);
  for (std::size_t r = 0; r < regions.size() && r < 30; ++r) {
    const auto& g = regions[r];
    const Eigen::Vector3f size = g.hi - g.lo;
    fmt::print("  region {:2d}: {:6d} points at ({:6.2f}, {:6.2f}, {:5.2f}) m, {:.2f} x {:.2f} x {:.2f} m, mean {:+.3f} m, max |{:.3f}| m\n",
               r, g.points, g.centroid.x(), g.centroid.y(), g.centroid.z(), size.x(), size.y(), size.z(), g.mean_m, g.max_abs_m);
  }
  if (j.contains("truth")) {
    const auto& t = j["truth"];
    fmt::print("against the scene's real differences ({} of {} labelled points changed): points precision {:.3f} recall {:.3f}; "
               "regions precision {:.3f} recall {:.3f}\n",
               t["changed_points"].get<std::size_t>(), t["labelled_points"].get<std::size_t>(), t["precision_points"].get<double>(),
               t["recall_points"].get<double>(), t["precision_regions"].get<double>(), t["recall_regions"].get<double>());
  }
  return kExitOk;
}

}  // namespace

void register_prior_map_commands(CLI::App& app, int& status) {
  CLI::App* prior = app.add_subcommand("prior-map", "Prior maps (BIM, design, earlier survey): prepare, deviations");
  prior->require_subcommand(1);
  auto o = std::make_shared<PrepareOptions>();
  CLI::App* prep = prior->add_subcommand("prepare", "Read a cloud (PLY, PCD, LAS) or mesh (PLY, OBJ, STL) and prepare it");
  prep->add_option("in", o->in, "Prior map file")->required();
  prep->add_option("--out", o->out, "Folder to write (prior_map.bin, points.ply)")->required();
  prep->add_option("--density", o->input.mesh_points_per_m2, "Mesh sampling, points per m²")
      ->check(CLI::PositiveNumber)->capture_default_str();
  prep->add_option("--scale", o->input.scale, "Multiply coordinates (0.001: the file is in millimetres)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  prep->add_option("--offset", o->offset, "x y z subtracted after scaling (the local origin in a site frame)")->expected(3);
  prep->add_option("--up", o->up, "The file's up axis (y: rotated to z up)")->check(CLI::IsMember({"z", "y"}))->capture_default_str();
  prep->callback([o, &status] { status = prepare(*o); });
  auto d = std::make_shared<DeviationOptions>();
  CLI::App* dev = prior->add_subcommand("deviations", "As-built against as-designed: a session's map against the prior");
  dev->add_option("session", d->session, "Session folder (map.ply, trajectory.tum)")->required();
  dev->add_option("--prior", d->prior, "Prior map: a prepared folder, or a cloud/mesh file")->required();
  dev->add_option("--out", d->out, "Folder for deviations.ply and deviations.json")->required();
  dev->add_option("--threshold", d->threshold_m, "Deviation that counts, m")->check(CLI::PositiveNumber)->capture_default_str();
  dev->add_option("--min-region-points", d->min_region_points, "Smaller regions are left out as noise")->capture_default_str();
  dev->add_option("--region-share", d->region_share, "A 0.2 m voxel joins a region when this share of its points deviates")
      ->check(CLI::Range(0.0F, 1.0F))->capture_default_str();
  dev->add_option("--smooth", d->smooth_m, "Average the deviations over voxels of this edge, m (0: raw)")->capture_default_str();
  dev->add_flag("--aligned", d->aligned, "The map is already in the prior's frame (no localisation)");
  dev->add_option("--truth-scene", d->truth_scene, "A simulated session's scene.ply: precision and recall of the real differences");
  dev->add_flag("--json", d->json, "Print the report as JSON");
  dev->callback([d, &status] { status = deviations(*d); });
}

}  // namespace adit::tools
