// adit eval traj: associate, align, then APE, RPE and KITTI drift.

#include <algorithm>
#include <array>
#include <optional>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/slam/align.hpp"
#include "adit/slam/ape.hpp"
#include "adit/slam/associate.hpp"
#include "adit/slam/kitti_drift.hpp"
#include "adit/slam/pose_error.hpp"
#include "adit/slam/rpe.hpp"
#include "adit/slam/trajectory_io.hpp"
#include "eval_commands.hpp"
#include "svg_plot.hpp"

namespace adit::tools {
namespace {

using namespace adit::slam;

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

void write_plots(const std::string& prefix, const Associated& a, std::span<const Pose> aligned,
                 const PoseErrors& ape) {
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

}  // namespace

void run_eval_traj(const TrajEvalOptions& o) {
  const Loaded ref = load(o.ref, o.ref_format, o.ref_times);
  const Loaded est = load(o.est, o.est_format, o.est_times);

  const Associated a = associate(ref.trajectory, est.trajectory, o.max_diff, o.offset);
  if (a.pairs.size() < 2) {
    if (!(ref.trajectory.timed && est.trajectory.timed) && ref.trajectory.size() != est.trajectory.size())
      throw InputError(o.est, "", fmt::format("{} poses against {} in the reference, and without times they can only "
                                              "be matched one to one; give --ref-times/--est-times",
                                              est.trajectory.size(), ref.trajectory.size()));
    throw InputError(o.est, "",
                     fmt::format("{} pose(s) associate with the reference within {} s (need 2): reference spans "
                                 "{:.3f}..{:.3f} s, estimate {:.3f}..{:.3f} s; check --max-diff and --offset",
                                 a.pairs.size(), o.max_diff, ref.trajectory.stamps.front(), ref.trajectory.stamps.back(),
                                 est.trajectory.stamps.front(), est.trajectory.stamps.back()));
  }

  const Alignment alignment = *parse_alignment(o.align);
  const auto fit = align_trajectory(a.ref, a.est, alignment);
  if (!fit)
    throw InputError(o.est, "align",
                     fmt::format("{} alignment is not determined: fewer than 3 associated positions or all on one line; "
                                 "use --align origin or none",
                                 o.align));
  std::vector<Pose> aligned;
  aligned.reserve(a.est.size());
  for (const Pose& p : a.est) aligned.push_back(fit->apply(p));

  const PoseErrors ape = absolute_pose_errors(a.ref, aligned);
  // Pairs along the (aligned) estimate by default, as evo chooses them.
  const bool on_ref = o.pairs_on == "ref";
  std::vector<double> pair_stamps = a.stamps;
  if (!on_ref)
    for (std::size_t k = 0; k < a.pairs.size(); ++k) pair_stamps[k] = est.trajectory.stamps[a.pairs[k].second];
  const RpeSettings rpe_settings{o.delta, *parse_delta_unit(o.delta_unit), o.all_pairs};
  if (rpe_settings.unit == DeltaUnit::seconds && !(on_ref ? ref : est).trajectory.timed)
    throw InputError(on_ref ? o.ref : o.est, "delta-unit", "seconds need times (KITTI: give --ref-times/--est-times)");
  const auto pairs = rpe_pairs(path_distances(on_ref ? std::span<const Pose>(a.ref) : std::span<const Pose>(aligned)),
                               pair_stamps, rpe_settings);
  if (pairs.empty())
    throw InputError("", "delta",
                     fmt::format("delta = {} {} gives no RPE pair on this trajectory; use a smaller delta", o.delta,
                                 o.delta_unit));
  const PoseErrors rpe = relative_pose_errors(a.ref, aligned, pairs);
  const auto kitti = kitti_drift(a.ref, aligned);

  const Stats ape_t = compute_stats(ape.translation), ape_r = compute_stats(ape.rotation_deg);
  const Stats rpe_t = compute_stats(rpe.translation), rpe_r = compute_stats(rpe.rotation_deg);
  const std::string rpe_label = fmt::format("{} {}, {}, chosen along the {}", o.delta, o.delta_unit,
                                            o.all_pairs ? "all pairs" : "consecutive", on_ref ? "reference" : "estimate");

  if (o.json) {
    nlohmann::json j;
    j["reference"] = {{"file", o.ref}, {"format", format_name(ref.format)}, {"poses", ref.trajectory.size()}};
    j["estimate"] = {{"file", o.est}, {"format", format_name(est.format)}, {"poses", est.trajectory.size()}};
    j["associated_pairs"] = a.pairs.size();
    j["max_diff_s"] = o.max_diff;
    j["alignment"] = {{"kind", o.align},
                      {"rotation", matrix_json(fit->rotation)},
                      {"translation", {fit->translation.x(), fit->translation.y(), fit->translation.z()}},
                      {"scale", fit->scale}};
    j["ape"] = {{"translation_m", stats_json(ape_t)}, {"rotation_deg", stats_json(ape_r)}};
    j["rpe"] = {{"delta", o.delta},
                {"unit", o.delta_unit},
                {"all_pairs", o.all_pairs},
                {"pairs_on", o.pairs_on},
                {"pairs", pairs.size()},
                {"translation_m", stats_json(rpe_t)},
                {"rotation_deg", stats_json(rpe_r)}};
    if (kitti) {
      nlohmann::json lengths = nlohmann::json::array();
      for (const auto& b : kitti->by_length)
        lengths.push_back({{"length_m", b.length},
                           {"segments", b.segments},
                           {"translation_percent", b.translation_percent},
                           {"rotation_deg_per_100m", b.rotation_deg_per_100m}});
      j["kitti"] = {{"segments", kitti->segments},
                    {"translation_percent", kitti->translation_percent},
                    {"rotation_deg_per_100m", kitti->rotation_deg_per_100m},
                    {"by_length", lengths}};
    } else {
      j["kitti"] = nullptr;
    }
    fmt::print("{}\n", j.dump(2));
  } else {
    fmt::print("reference   {} ({}, {} poses)\n", o.ref, format_name(ref.format), ref.trajectory.size());
    fmt::print("estimate    {} ({}, {} poses)\n", o.est, format_name(est.format), est.trajectory.size());
    fmt::print("associated  {} pairs (max difference {} s)\n", a.pairs.size(), o.max_diff);
    fmt::print("alignment   {}: rotation {:.4f} deg, translation ({:.4f}, {:.4f}, {:.4f}) m, scale {:.6f}\n\n", o.align,
               rad_to_deg(rotation_angle(fit->rotation)), fit->translation.x(), fit->translation.y(),
               fit->translation.z(), fit->scale);
    fmt::print("{}", stats_header());
    fmt::print("{}", stats_row("APE translation (m)", ape_t));
    fmt::print("{}", stats_row("APE rotation (deg)", ape_r));
    fmt::print("{}", stats_row("RPE translation (m)", rpe_t));
    fmt::print("{}", stats_row("RPE rotation (deg)", rpe_r));
    fmt::print("  RPE pairs: {}\n\n", rpe_label);
    if (kitti) {
      fmt::print("KITTI drift over {} segments: {:.4f} % translation, {:.4f} deg/100 m rotation\n", kitti->segments,
                 kitti->translation_percent, kitti->rotation_deg_per_100m);
      fmt::print("  {:>8} {:>9} {:>10} {:>14}\n", "length", "segments", "trans %", "rot deg/100m");
      for (const auto& b : kitti->by_length)
        if (b.segments > 0)
          fmt::print("  {:>6.0f} m {:>9} {:>10.4f} {:>14.4f}\n", b.length, b.segments, b.translation_percent,
                     b.rotation_deg_per_100m);
    } else {
      fmt::print("KITTI drift: n/a (the reference path is shorter than 100 m)\n");
    }
  }

  if (!o.svg_prefix.empty()) write_plots(o.svg_prefix, a, aligned, ape);
  if (!o.save_aligned.empty()) {
    Trajectory out;
    out.stamps = a.stamps;
    out.poses = aligned;
    write_tum(o.save_aligned, out);
  }
}

}  // namespace adit::tools
