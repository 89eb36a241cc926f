// adit prior-map prepare: a prior map (BIM export, design model, earlier
// survey) read, downsampled, given normals and a plan view, and written as a
// folder aditd and the benchmarks load (docs/PRIOR-MAP.md).

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/protocol/map_export.hpp"
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
}

}  // namespace adit::tools
