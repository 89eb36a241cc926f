// adit eval traj: associate, align, then APE, RPE and KITTI drift.

#include <algorithm>
#include <array>
#include <optional>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/eval/align.hpp"
#include "adit/eval/ape.hpp"
#include "adit/eval/associate.hpp"
#include "adit/eval/kitti_drift.hpp"
#include "adit/eval/path.hpp"
#include "adit/eval/pose_error.hpp"
#include "adit/eval/rpe.hpp"
#include "adit/eval/trajectory_io.hpp"
#include "adit/slam/tum.hpp"
#include "eval_commands.hpp"
#include "adit/products/svg_plot.hpp"

namespace adit::tools {

using products::kColorEstimate;
using products::kColorReference;
using products::kColorSecond;
using products::Plot;
using products::PlotSeries;
using products::SeriesStyle;
using products::write_svg;
namespace {

using namespace adit::slam;
using namespace adit::eval;

struct Loaded {
  Trajectory trajectory;
  TrajectoryFormat format;
};

std::string_view format_name(TrajectoryFormat f) {
  switch (f) {
    case TrajectoryFormat::tum: return "tum";
    case TrajectoryFormat::kitti: return "kitti";
    case TrajectoryFormat::euroc: return "euroc";
  }
  return "?";
}

Loaded load(const std::string& path, const std::string& format, const std::string& times) {
  const TrajectoryFormat f = format == "auto" ? detect_trajectory_format(path) : *parse_trajectory_format(format);
  if (!times.empty() && f != TrajectoryFormat::kitti)
    throw InputError(times, "", "a times file applies to KITTI poses only");
  std::optional<std::filesystem::path> times_path;
  if (!times.empty()) times_path = times;
  return {read_trajectory(path, f, times_path), f};
}

// The two axes along which the reference spreads most: the plan view.
std::array<int, 2> plan_axes(std::span<const Pose> poses) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const Pose& p : poses) {
    lo = lo.cwiseMin(p.translation());
    hi = hi.cwiseMax(p.translation());
  }
  const Eigen::Vector3d extent = hi - lo;
  int smallest = 0;
  extent.minCoeff(&smallest);
  return smallest == 0 ? std::array{1, 2} : smallest == 1 ? std::array{0, 2} : std::array{0, 1};
}

void write_plots(const std::string& prefix, const Associated& a, std::span<const Pose> aligned, const PoseErrors& ape) {
  const auto [u, v] = plan_axes(a.ref);
  const char* axis = "xyz";
  Plot plan{"Trajectories, plan view", fmt::format("{} (m)", axis[u]), fmt::format("{} (m)", axis[v]), {}, {}, true};
  // The reference drawn wide and light under the estimate, so both stay visible.
  PlotSeries ref{"reference", kColorReference, SeriesStyle::line, {}, {}, 4.0};
  PlotSeries est{"estimate (aligned)", kColorEstimate, SeriesStyle::line, {}, {}, 1.2};
  for (std::size_t i = 0; i < a.ref.size(); ++i) {
    ref.x.push_back(a.ref[i].translation()(u));
    ref.y.push_back(a.ref[i].translation()(v));
    est.x.push_back(aligned[i].translation()(u));
    est.y.push_back(aligned[i].translation()(v));
  }
  plan.series = {ref, est};
  write_svg(prefix + "-plan.svg", plan);

  Plot along{"Absolute position error along the path", "distance along the reference path (m)", "APE (m)", {}, {}};
  PlotSeries err{"APE translation", kColorEstimate, SeriesStyle::line, path_distances(a.ref), ape.translation};
  along.series = {err};
  write_svg(prefix + "-ape.svg", along);
}

nlohmann::json matrix_json(const Eigen::Matrix3d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
  return rows;
}

// Everything `adit eval traj` computed, for printing and plotting.
struct TrajEvaluation {
  Loaded ref, est;
  Associated associated;
  Similarity fit;
  std::vector<Pose> aligned;  // associated estimate poses after the fit
  PoseErrors ape, rpe;
  std::size_t rpe_pairs = 0;
  std::optional<KittiDrift> kitti;
};

TrajEvaluation evaluate(const TrajEvalOptions& o) {
  TrajEvaluation e{
      load(o.ref, o.ref_format, o.ref_times), load(o.est, o.est_format, o.est_times), {}, {}, {}, {}, {}, 0, {}};
  const Trajectory& ref = e.ref.trajectory;
  const Trajectory& est = e.est.trajectory;

  e.associated = associate(ref, est, o.max_diff, o.offset);
  const Associated& a = e.associated;
  if (a.pairs.size() < 2) {
    if (!(ref.timed && est.timed) && ref.size() != est.size())
      throw InputError(o.est, "",
                       fmt::format("{} poses against {} in the reference, and without times they can only "
                                   "be matched one to one; give --ref-times/--est-times",
                                   est.size(), ref.size()));
    throw InputError(o.est, "",
                     fmt::format("{} pose(s) associate with the reference within {} s (need 2): reference spans "
                                 "{:.3f}..{:.3f} s, estimate {:.3f}..{:.3f} s; check --max-diff and --offset",
                                 a.pairs.size(), o.max_diff, ref.stamps.front(), ref.stamps.back(), est.stamps.front(),
                                 est.stamps.back()));
  }

  const auto fit = align_trajectory(a.ref, a.est, *parse_alignment(o.align));
  if (!fit)
    throw InputError(
        o.est, "align",
        fmt::format("{} alignment is not determined: fewer than 3 associated positions or all on one line; "
                    "use --align origin or none",
                    o.align));
  e.fit = *fit;
  e.aligned.reserve(a.est.size());
  for (const Pose& p : a.est) e.aligned.push_back(fit->apply(p));
  e.ape = absolute_pose_errors(a.ref, e.aligned);

  // Pairs along the (aligned) estimate by default, as evo chooses them.
  const bool on_ref = o.pairs_on == "ref";
  std::vector<double> pair_stamps = a.stamps;
  if (!on_ref)
    for (std::size_t k = 0; k < a.pairs.size(); ++k) pair_stamps[k] = est.stamps[a.pairs[k].second];
  const RpeSettings settings{o.delta, *parse_delta_unit(o.delta_unit), o.all_pairs};
  if (settings.unit == DeltaUnit::seconds && !(on_ref ? ref : est).timed)
    throw InputError(on_ref ? o.ref : o.est, "delta-unit", "seconds need times (KITTI: give --ref-times/--est-times)");
  const std::span<const Pose> along = on_ref ? std::span<const Pose>(a.ref) : std::span<const Pose>(e.aligned);
  const auto pairs = rpe_pairs(path_distances(along), pair_stamps, settings);
  if (pairs.empty())
    throw InputError(
        "", "delta",
        fmt::format("delta = {} {} gives no RPE pair on this trajectory; use a smaller delta", o.delta, o.delta_unit));
  e.rpe = relative_pose_errors(a.ref, e.aligned, pairs);
  e.rpe_pairs = pairs.size();
  e.kitti = kitti_drift(a.ref, e.aligned);
  return e;
}

void print_json(const TrajEvalOptions& o, const TrajEvaluation& e) {
  nlohmann::json j;
  j["reference"] = {{"file", o.ref}, {"format", format_name(e.ref.format)}, {"poses", e.ref.trajectory.size()}};
  j["estimate"] = {{"file", o.est}, {"format", format_name(e.est.format)}, {"poses", e.est.trajectory.size()}};
  j["associated_pairs"] = e.associated.pairs.size();
  j["max_diff_s"] = o.max_diff;
  j["alignment"] = {{"kind", o.align},
                    {"rotation", matrix_json(e.fit.rotation)},
                    {"translation", {e.fit.translation.x(), e.fit.translation.y(), e.fit.translation.z()}},
                    {"scale", e.fit.scale}};
  j["ape"] = {{"translation_m", stats_json(compute_stats(e.ape.translation))},
              {"rotation_deg", stats_json(compute_stats(e.ape.rotation_deg))}};
  j["rpe"] = {{"delta", o.delta},
              {"unit", o.delta_unit},
              {"all_pairs", o.all_pairs},
              {"pairs_on", o.pairs_on},
              {"pairs", e.rpe_pairs},
              {"translation_m", stats_json(compute_stats(e.rpe.translation))},
              {"rotation_deg", stats_json(compute_stats(e.rpe.rotation_deg))}};
  j["kitti"] = nullptr;
  if (e.kitti) {
    nlohmann::json lengths = nlohmann::json::array();
    for (const auto& b : e.kitti->by_length)
      lengths.push_back({{"length_m", b.length},
                         {"segments", b.segments},
                         {"translation_percent", b.translation_percent},
                         {"rotation_deg_per_100m", b.rotation_deg_per_100m}});
    j["kitti"] = {{"segments", e.kitti->segments},
                  {"translation_percent", e.kitti->translation_percent},
                  {"rotation_deg_per_100m", e.kitti->rotation_deg_per_100m},
                  {"by_length", lengths}};
  }
  fmt::print("{}\n", j.dump(2));
}

void print_table(const TrajEvalOptions& o, const TrajEvaluation& e) {
  fmt::print("reference   {} ({}, {} poses)\n", o.ref, format_name(e.ref.format), e.ref.trajectory.size());
  fmt::print("estimate    {} ({}, {} poses)\n", o.est, format_name(e.est.format), e.est.trajectory.size());
  fmt::print("associated  {} pairs (max difference {} s)\n", e.associated.pairs.size(), o.max_diff);
  fmt::print("alignment   {}: rotation {:.4f} deg, translation ({:.4f}, {:.4f}, {:.4f}) m, scale {:.6f}\n\n", o.align,
             rad_to_deg(rotation_angle(e.fit.rotation)), e.fit.translation.x(), e.fit.translation.y(),
             e.fit.translation.z(), e.fit.scale);
  fmt::print("{}", stats_header());
  fmt::print("{}", stats_row("APE translation (m)", compute_stats(e.ape.translation)));
  fmt::print("{}", stats_row("APE rotation (deg)", compute_stats(e.ape.rotation_deg)));
  fmt::print("{}", stats_row("RPE translation (m)", compute_stats(e.rpe.translation)));
  fmt::print("{}", stats_row("RPE rotation (deg)", compute_stats(e.rpe.rotation_deg)));
  fmt::print("  RPE pairs: {} {}, {}, chosen along the {}\n\n", o.delta, o.delta_unit,
             o.all_pairs ? "all pairs" : "consecutive", o.pairs_on == "ref" ? "reference" : "estimate");
  if (!e.kitti) {
    fmt::print("KITTI drift: n/a (the reference path is shorter than 100 m)\n");
    return;
  }
  fmt::print("KITTI drift over {} segments: {:.4f} % translation, {:.4f} deg/100 m rotation\n", e.kitti->segments,
             e.kitti->translation_percent, e.kitti->rotation_deg_per_100m);
  fmt::print("  {:>8} {:>9} {:>10} {:>14}\n", "length", "segments", "trans %", "rot deg/100m");
  for (const auto& b : e.kitti->by_length)
    if (b.segments > 0)
      fmt::print("  {:>6.0f} m {:>9} {:>10.4f} {:>14.4f}\n", b.length, b.segments, b.translation_percent,
                 b.rotation_deg_per_100m);
}

}  // namespace

void run_eval_traj(const TrajEvalOptions& o) {
  const TrajEvaluation e = evaluate(o);
  if (o.json)
    print_json(o, e);
  else
    print_table(o, e);
  if (!o.svg_prefix.empty()) write_plots(o.svg_prefix, e.associated, e.aligned, e.ape);
  if (!o.save_aligned.empty()) {
    Trajectory out;
    out.stamps = e.associated.stamps;
    out.poses = e.aligned;
    write_tum(o.save_aligned, out);
  }
}

}  // namespace adit::tools
