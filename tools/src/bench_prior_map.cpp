// adit bench prior-map: global localisation from random starts of a simulated
// session against its prior (the session's bim.ply, or --prior). Each start
// accumulates a second of scans in a gravity-levelled frame at that start,
// placed with the true sensor motion (what the odometry gives over one second,
// to millimetres: docs/ODOMETRY.md) and levelled with a tilt error drawn as an
// accelerometer's; slam::localise sees the cloud and the prior only. A start
// counts as localised when it is reported found and lies within 0.05 m and
// 0.5° of the truth; a start reported found beyond that is a false localisation.
// Each try accepts as aditd's: with confirmation, at a confirmed pair's
// overlap threshold (slam::confirmed_localisation), so the first try's figures
// are those of one such try. A start goes on as aditd would (prior_localiser.hpp) until --retry-s of
// sensor time have passed: after a failed try, later scans are tried; a found
// pose is taken once the next try agrees (slam/anchor_confirmation.hpp;
// --no-confirm: at once). localisation_success_rate counts the first try
// alone, localisation_success_rate_retrying what aditd would take within the
// budget. With --hint-m, a crew's hint given once at the start narrows every
// try, its heading turned with the payload as aditd turns it.

#include "bench_prior_map.hpp"

#include <algorithm>
#include <deque>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <random>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "adit/common/clock.hpp"
#include "adit/common/error.hpp"
#include "adit/common/quantile.hpp"
#include "adit/config/load.hpp"
#include "adit/daemon/prior_localiser.hpp"
#include "adit/eval/align.hpp"
#include "adit/eval/associate.hpp"
#include "adit/eval/interpolate.hpp"
#include "adit/eval/trajectory_io.hpp"
#include "adit/slam/anchor_confirmation.hpp"
#include "adit/slam/global_localisation.hpp"
#include "bench_prior_drift.hpp"
#include "bench_scans.hpp"
#include "prior_map_source.hpp"

namespace adit::tools {
namespace {

struct Options {
  std::string session;
  std::string prior;
  std::string prior_trajectory;  // the prior's session: its estimated trajectory (the prior's frame) ...
  std::string prior_truth;       // ... and its truth, which place the prior's frame in the world
  int starts = 40;
  int scans = 10;
  std::uint64_t seed = 1;
  double hint_m = 0.0;           // > 0: give a hint this far off (at most), heading within 10°
  double tilt_sigma_deg = 0.3;   // the levelling's error (accelerometer, 1 mg ≈ 0.06°, plus motion)
  bool json = false;
  bool drift = true;             // the odometry with and without the prior (bench_prior_drift.hpp)
  double prior_sigma_m = 0.0;    // > 0: the odometry's prior_map_sigma_m for the anchored run
  int prior_stride = 0;          // > 0: its prior_map_stride
  bool confirm = true;           // a found try counts once the next found one agrees (aditd's prior_map.confirm)
  double retry_s = 10.0;         // try again as aditd does for this long (sensor time from the start); 0: one try
  double min_overlap = 0.0;      // > 0: the acceptance's overlap threshold instead of slam's default
  int search_levels = -1;        // >= 0: the plan search's depth instead of slam's default
  bool exhaustive_baseline = false;  // each try again with every plan cell scored: CPU ratio and same result
};

struct Start {
  std::size_t scan = 0;
  bool reported = false;
  bool within = false;
  double error_m = 0.0;
  double error_deg = 0.0;
  double seconds = 0.0;
  std::string failure;
  // Trying again as aditd does, within Options::retry_s of sensor time.
  int tries = 0;
  bool retry_reported = false;
  bool retry_within = false;
  double time_to_localise_s = 0.0;  // from the start's first scan to the found try's result (its CPU time included)
};

// A crew's hint (--hint-m), given once at the start: where they stood, off by
// up to hint_m, and the way the payload faced, off by up to 10°.
struct CrewHint {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  // prior frame
  double heading_error_rad = 0.0;
};

struct Try {
  slam::LocalisationResult result;
  double cpu_s = 0.0;
  double error_m = 0.0;
  double error_deg = 0.0;
  bool within = false;
  Eigen::Isometry3d level = Eigen::Isometry3d::Identity();  // the cloud's frame in the world (the odometry's here)
};

Eigen::Isometry3d yaw_only(const Eigen::Isometry3d& pose) {
  const Eigen::Vector3d x = pose.linear().col(0);
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = Eigen::AngleAxisd(std::atan2(x.y(), x.x()), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  out.translation() = pose.translation();
  return out;
}

int run(const Options& o) {
  const std::filesystem::path dir(o.session);
  const config::Config cfg = config::load_config(dir / "session.yaml");
  BenchInput input;
  input.pcap = cfg.lidar.pcap;
  input.model = cfg.lidar.model;
  input.calibration = cfg.lidar.calibration;
  const std::vector<BenchScan> scans = load_bench_scans(input);
  const slam::Trajectory truth = eval::read_tum(dir / "truth_sensor.tum");
  if (static_cast<int>(scans.size()) < o.scans + 1) throw InputError(o.session, "", "too few scans for one start");

  const std::filesystem::path prior_path = o.prior.empty() ? dir / "bim.ply" : std::filesystem::path(o.prior);
  const LoadedPrior prior = load_prior(prior_path);
  const slam::VoxelHashMap index = slam::index_prior_map(prior.map);
  // The prior's frame in the world: the world itself (bim.ply), or where the
  // prior session's trajectory lies on its truth.
  Eigen::Isometry3d world_from_prior = Eigen::Isometry3d::Identity();
  if (!o.prior_trajectory.empty()) {
    const slam::Trajectory est = eval::read_tum(o.prior_trajectory);
    const eval::Associated a = eval::associate(eval::read_tum(o.prior_truth), est, 0.02);
    const auto fit = eval::align_trajectory(a.ref, a.est, eval::Alignment::se3);
    if (!fit) throw InputError(o.prior_trajectory, "", "cannot be aligned with --prior-truth");
    world_from_prior.linear() = fit->rotation;
    world_from_prior.translation() = fit->translation;
  }

  std::mt19937_64 rng(o.seed);
  std::uniform_int_distribution<std::size_t> pick(0, scans.size() - static_cast<std::size_t>(o.scans) - 1);
  std::normal_distribution<double> tilt(0.0, o.tilt_sigma_deg * std::numbers::pi / 180.0);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto stamp_s = [&](std::size_t j) { return 1e-9 * static_cast<double>(scans[j].stamp_ns); };
  const double period_s = (stamp_s(scans.size() - 1) - stamp_s(0)) / static_cast<double>(scans.size() - 1);
  // When the window of scans from `first` is all in: the next scan's stamp.
  const auto window_end_s = [&](std::size_t first) {
    const std::size_t next = first + static_cast<std::size_t>(o.scans);
    return next < scans.size() ? stamp_s(next) : stamp_s(scans.size() - 1) + period_s;
  };
  // Each try as aditd makes it: a confirmed pair's acceptance with --confirm.
  slam::LocalisationConfig localisation = o.confirm ? slam::confirmed_localisation() : slam::LocalisationConfig{};
  if (o.min_overlap > 0.0) localisation.min_overlap = o.min_overlap;
  if (o.search_levels >= 0) localisation.search_levels = o.search_levels;
  slam::LocalisationConfig exhaustive = localisation;
  exhaustive.search_levels = 0;
  // --exhaustive-baseline: each try's CPU time searched both ways, and whether the results are the same.
  std::vector<double> searched_cpu_s, exhaustive_cpu_s;
  std::size_t baseline_differs = 0;
  std::vector<Start> starts;
  std::vector<Eigen::Vector3f> cloud;
  // One try: the window of o.scans scans from `first`, levelled at its first
  // scan with the start's tilt error (an accelerometer's error changes slowly).
  const auto try_window = [&](std::size_t first, double tilt_x, double tilt_y, std::optional<CrewHint>& crew) {
    Try attempt;
    const auto sensor0 = eval::interpolate_pose(truth, stamp_s(first));
    if (!sensor0) throw InputError(dir / "truth_sensor.tum", "", fmt::format("no truth at {:.3f} s", stamp_s(first)));
    // The levelled frame: the sensor's position and heading, tilted by the levelling's error.
    Eigen::Isometry3d level = yaw_only(*sensor0);
    level.linear() = level.linear() * (Eigen::AngleAxisd(tilt_x, Eigen::Vector3d::UnitX()) *
                                       Eigen::AngleAxisd(tilt_y, Eigen::Vector3d::UnitY())).toRotationMatrix();
    const Eigen::Isometry3d level_inv = level.inverse();
    cloud.clear();
    for (std::size_t j = first; j < first + static_cast<std::size_t>(o.scans); ++j) {
      const BenchScan& scan = scans[j];
      const bool timed = scan.time_offsets_ns.size() == scan.points.size();
      // The motion within a sweep, at 1 ms steps (a sensor moves under 2 mm in one).
      double cached_t = -1.0;
      Eigen::Isometry3f to_level = Eigen::Isometry3f::Identity();
      for (std::size_t k = 0; k < scan.points.size(); ++k) {
        const double t = stamp_s(j) + (timed ? std::floor(1e3 * scan.time_s(k)) * 1e-3 : 0.0);
        if (t != cached_t) {
          const auto pose = eval::interpolate_pose(truth, t);
          if (!pose) continue;
          to_level = (level_inv * *pose).cast<float>();
          cached_t = t;
        }
        cloud.push_back(to_level * scan.points[k]);
      }
    }
    // The hint stays where the crew gave it; its heading turns with the
    // payload, as aditd turns it by the odometry (PriorLocaliser::search_hint).
    std::optional<slam::LocalisationHint> hint;
    if (o.hint_m > 0.0) {
      const Eigen::Isometry3d prior_level = world_from_prior.inverse() * level;
      if (!crew) {
        CrewHint c;
        c.position = prior_level.translation().head<2>() + o.hint_m * Eigen::Vector2d(unit(rng), unit(rng)) / std::sqrt(2.0);
        c.heading_error_rad = unit(rng) * 10.0 * std::numbers::pi / 180.0;
        crew = c;
      }
      slam::LocalisationHint h;
      h.position = crew->position;
      h.radius_m = 2.0 * o.hint_m;
      const Eigen::Vector3d x = prior_level.linear().col(0);
      h.yaw_rad = std::atan2(x.y(), x.x()) + crew->heading_error_rad;
      h.yaw_tolerance_rad = 20.0 * std::numbers::pi / 180.0;
      hint = h;
    }
    const std::int64_t c0 = thread_cpu_ns();
    attempt.result = slam::localise(cloud, prior.map, index, hint, localisation);
    attempt.cpu_s = 1e-9 * static_cast<double>(thread_cpu_ns() - c0);
    if (o.exhaustive_baseline) {
      const std::int64_t e0 = thread_cpu_ns();
      const slam::LocalisationResult every_cell = slam::localise(cloud, prior.map, index, hint, exhaustive);
      exhaustive_cpu_s.push_back(1e-9 * static_cast<double>(thread_cpu_ns() - e0));
      searched_cpu_s.push_back(attempt.cpu_s);
      if (every_cell.success != attempt.result.success || every_cell.pose.matrix() != attempt.result.pose.matrix() ||
          every_cell.failure != attempt.result.failure)
        ++baseline_differs;
    }
    const Eigen::Isometry3d error = (world_from_prior * attempt.result.pose).inverse() * level;
    attempt.error_m = error.translation().norm();
    attempt.error_deg = Eigen::AngleAxisd(error.linear()).angle() * 180.0 / std::numbers::pi;
    attempt.within = attempt.error_m <= 0.05 && attempt.error_deg <= 0.5;
    attempt.level = level;
    return attempt;
  };
  for (int s = 0; s < o.starts; ++s) {
    Start start;
    start.scan = pick(rng);
    const double tilt_x = tilt(rng);
    const double tilt_y = tilt(rng);
    const double t0 = stamp_s(start.scan);
    std::optional<CrewHint> crew;
    Try attempt = try_window(start.scan, tilt_x, tilt_y, crew);
    const slam::LocalisationResult& r = attempt.result;
    start.seconds = attempt.cpu_s;
    start.error_m = attempt.error_m;
    start.error_deg = attempt.error_deg;
    start.reported = r.success;
    start.within = attempt.within;
    start.failure = r.failure;
    if (!o.json)
      fmt::print("start {:2d} scan {:5d}: {} error {:.3f} m {:.2f} deg, overlap {:.2f} rival {:.2f} at {:.1f} m, weakest {:.3f} sigma {:.3f} m {:.3f} deg, {:.2f} s{}{}\n", s,
                 start.scan, r.success ? (start.within ? "found " : "FALSE ") : "failed", start.error_m,
                 start.error_deg, r.overlap, r.rival_overlap, r.rival_distance_m, r.weakest_eigenvalue, r.position_sigma_m, r.yaw_sigma_rad * 180 / std::numbers::pi, start.seconds, r.success ? "" : ": ",
                 r.success ? "" : r.failure);
    // As aditd goes on (prior_localiser.hpp), scan by scan: two windows, the
    // next gathered while a try searches the other; a search begins when its
    // window is in and the search before it has ended; after the k-th failure
    // scans_passed_over(k) scans are passed over before the next window
    // begins (none while a found pose waits); until one is reported found or
    // the budget's sensor time has passed.
    slam::AnchorConfirmation confirmation(localisation);  // a found anchor waits for the next try to agree
    std::uint64_t failures = 0;
    struct Search {
      std::size_t first = 0;
      double done_s = 0.0;  // sensor time the search ends
      Try attempt;
    };
    // The prior thread's search under way: the first window's, from when its scans are in.
    std::optional<Search> searching = Search{start.scan, window_end_s(start.scan) + attempt.cpu_s, attempt};
    std::deque<std::size_t> ready;    // windows in, not yet searched (their first scans)
    double prior_free_s = t0;         // when the prior thread ended its last search
    int pass_over = 0;                // posted by a failure, taken by the odometry thread
    bool found = false;
    // The prior thread up to sensor time `t`: ends the search under way, begins the next.
    const auto advance_prior = [&](double t) {
      for (;;) {
        if (searching && searching->done_s <= t) {
          const Search done = *std::move(searching);
          searching.reset();
          prior_free_s = done.done_s;
          ++start.tries;
          if (done.first != start.scan && !o.json)
            fmt::print("         try {} at scan {:5d}: {} error {:.3f} m {:.2f} deg, overlap {:.2f} rival {:.2f} at {:.1f} m, {:.2f} s{}{}\n",
                       start.tries, done.first, done.attempt.result.success ? (done.attempt.within ? "found " : "FALSE ") : "failed",
                       done.attempt.error_m, done.attempt.error_deg, done.attempt.result.overlap, done.attempt.result.rival_overlap,
                       done.attempt.result.rival_distance_m, done.attempt.cpu_s, done.attempt.result.success ? "" : ": ",
                       done.attempt.result.success ? "" : done.attempt.result.failure);
          // The anchor a try implies: prior ← world (the odometry's frame here).
          const Eigen::Isometry3d anchor = done.attempt.result.pose * done.attempt.level.inverse();
          if (done.attempt.result.success && (!o.confirm || confirmation.agrees(anchor, done.attempt.level))) {
            start.retry_reported = true;
            start.retry_within = done.attempt.within;
            start.time_to_localise_s = done.done_s - t0;
            found = true;
            return;
          }
          if (!done.attempt.result.success)
            pass_over = daemon::scans_passed_over(++failures, o.scans, confirmation.waiting());
          continue;
        }
        if (!searching && !ready.empty()) {
          const std::size_t first = ready.front();
          ready.pop_front();
          Try next = try_window(first, tilt_x, tilt_y, crew);
          const double begin_s = std::max(window_end_s(first), prior_free_s);
          searching = Search{first, begin_s + next.cpu_s, std::move(next)};
          continue;
        }
        return;
      }
    };
    // The odometry thread, scan by scan after the first window (none with --retry-s 0: one try).
    int skip = 0;
    int in_window = 0;
    std::size_t window_first = start.scan;
    for (std::size_t j = start.scan + static_cast<std::size_t>(o.scans); o.retry_s > 0.0 && j < scans.size(); ++j) {
      advance_prior(std::min(stamp_s(j), t0 + o.retry_s));
      if (found || stamp_s(j) - t0 > o.retry_s) break;
      if (ready.size() + (searching ? 1 : 0) >= 2) continue;  // both windows are the prior thread's
      if (pass_over > 0) skip = std::exchange(pass_over, 0);
      if (in_window == 0 && skip > 0) {
        --skip;
        continue;
      }
      if (in_window == 0) window_first = j;
      if (++in_window == o.scans) {
        ready.push_back(window_first);
        in_window = 0;
      }
    }
    if (!found) advance_prior(o.retry_s > 0.0 ? t0 + o.retry_s : std::numeric_limits<double>::infinity());
    starts.push_back(start);
  }
  const auto count = [&](auto pred) { return static_cast<int>(std::count_if(starts.begin(), starts.end(), pred)); };
  const int found = count([](const Start& s) { return s.reported && s.within; });
  const int wrong = count([](const Start& s) { return s.reported && !s.within; });
  const int failed = count([](const Start& s) { return !s.reported; });
  const int failed_near = count([](const Start& s) { return !s.reported && s.within; });
  // Within the budget (with --retry-s 0, one try, whatever it took).
  const int found_retrying = count([&](const Start& s) {
    return s.retry_reported && s.retry_within && (o.retry_s <= 0.0 || s.time_to_localise_s <= o.retry_s);
  });
  const int wrong_retrying = count([](const Start& s) { return s.retry_reported && !s.retry_within; });
  std::vector<double> times_to_localise;
  for (const Start& s : starts)
    if (s.retry_reported && s.retry_within) times_to_localise.push_back(s.time_to_localise_s);
  const double rate_retrying = static_cast<double>(found_retrying) / static_cast<double>(starts.size());
  const double median_time_s = times_to_localise.empty() ? 0.0 : quantile(times_to_localise, 0.5);
  const double max_time_s =
      times_to_localise.empty() ? 0.0 : *std::max_element(times_to_localise.begin(), times_to_localise.end());
  std::vector<double> seconds;
  std::vector<double> err_m, err_deg;
  for (const Start& s : starts) {
    seconds.push_back(s.seconds);
    if (s.reported && s.within) {
      err_m.push_back(s.error_m);
      err_deg.push_back(s.error_deg);
    }
  }
  std::map<std::string, int> reasons;
  for (const Start& s : starts)
    if (!s.reported) ++reasons[s.failure.substr(0, s.failure.find_first_of(":0123456789"))];
  const double rate = static_cast<double>(found) / static_cast<double>(starts.size());
  const double median_s = quantile(seconds, 0.5);
  const double searched_total_s = std::accumulate(searched_cpu_s.begin(), searched_cpu_s.end(), 0.0);
  const double exhaustive_total_s = std::accumulate(exhaustive_cpu_s.begin(), exhaustive_cpu_s.end(), 0.0);
  const double max_s = *std::max_element(seconds.begin(), seconds.end());
  const std::size_t memory = prior_map_bytes(prior.map);
  std::optional<PriorDrift> drift;
  if (o.drift) drift = measure_prior_drift(dir, scans, prior.map, index, world_from_prior, o.scans, o.prior_sigma_m, o.prior_stride);
  const auto run_json = [](const DriftRun& r) {
    nlohmann::json j;
    j["anchored"] = r.anchored;
    j["anchored_at_s"] = r.anchored_at_s;
    j["localisation_tries"] = r.localisation_tries;
    j["failure"] = r.failure;
    j["path_m"] = r.path_m;
    j["end_error_m"] = r.end_error_m;
    j["drift_percent"] = r.drift_percent;
    j["ape_rms_m"] = r.ape_rms_m;
    j["ape_max_m"] = r.ape_max_m;
    j["ape_max_deg"] = r.ape_max_deg;
    j["ape_fitted_rms_m"] = std::isnan(r.ape_fitted_rms_m) ? nlohmann::json() : nlohmann::json(r.ape_fitted_rms_m);
    j["odometry_median_ms"] = r.odometry_median_ms;
    j["odometry_p99_ms"] = r.odometry_p99_ms;
    j["invalid_poses"] = r.invalid_poses;
    return j;
  };
  if (o.json) {
    nlohmann::json j;
    j["session"] = o.session;
    j["prior"] = prior_path.string();
    j["prior_points"] = prior.map.points.size();
    j["prior_memory_mb"] = 1e-6 * static_cast<double>(memory);
    j["prepare_s"] = prior.prepare_s;
    j["starts"] = starts.size();
    j["scans_per_start"] = o.scans;
    j["localisation_success_rate"] = rate;
    j["false_localisations"] = wrong;
    j["failed"] = failed;
    j["failed_but_near"] = failed_near;
    j["median_localisation_s"] = median_s;
    j["max_localisation_s"] = max_s;
    j["median_error_m"] = err_m.empty() ? 0.0 : quantile(err_m, 0.5);
    j["median_error_deg"] = err_deg.empty() ? 0.0 : quantile(err_deg, 0.5);
    j["failure_reasons"] = reasons;
    j["min_overlap"] = localisation.min_overlap;
    j["confirm"] = o.confirm;
    j["retry_s"] = o.retry_s;
    j["localisation_success_rate_retrying"] = rate_retrying;
    j["false_localisations_retrying"] = wrong_retrying;
    j["median_time_to_localise_s"] = median_time_s;
    j["max_time_to_localise_s"] = max_time_s;
    if (!searched_cpu_s.empty()) {
      j["search_levels"] = localisation.search_levels;
      j["search_cpu_s"] = searched_total_s;
      j["exhaustive_search_cpu_s"] = exhaustive_total_s;
      j["exhaustive_results_differ"] = baseline_differs;
    }
    // Null when not measured (--no-drift), or when the odometry never localised against the prior.
    j["drift_percent_with_prior"] = drift && drift->with_prior.anchored ? nlohmann::json(drift->with_prior.drift_percent) : nlohmann::json();
    j["drift_percent_without_prior"] = drift ? nlohmann::json(drift->without_prior.drift_percent) : nlohmann::json();
    if (drift) {
      j["with_prior"] = run_json(drift->with_prior);
      j["without_prior"] = run_json(drift->without_prior);
    }
    fmt::print("{}\n", j.dump(2));
    return kExitOk;
  }
  fmt::print("prior: {} ({} points, {:.1f} MB prepared{})\n", prior_path.string(), prior.map.points.size(),
             1e-6 * static_cast<double>(memory),
             prior.prepared_now ? fmt::format(", read and prepared in {:.1f} s", prior.prepare_s) : "");
  fmt::print("starts: {} of {} scans each\n", starts.size(), o.scans);
  fmt::print("localisation_success_rate {:.3f} ({} of {} within 0.05 m and 0.5 deg; one try, overlap >= {:.2f})\n", rate,
             found, starts.size(), localisation.min_overlap);
  fmt::print("false_localisations {}\n", wrong);
  fmt::print("failed {} ({} of them were near the truth)\n", failed, failed_near);
  for (const auto& [why, n] : reasons) fmt::print("  {} x {}\n", n, why);
  fmt::print("median_localisation_s {:.2f} (max {:.2f}, one core, CPU time)\n", median_s, max_s);
  if (!searched_cpu_s.empty()) {
    fmt::print("search_levels {}: {:.2f} s of CPU over {} tries against {:.2f} s with every plan cell scored "
               "(ratio {:.3f}; median try {:.2f} s against {:.2f} s); results differ in {}\n",
               localisation.search_levels, searched_total_s, searched_cpu_s.size(), exhaustive_total_s,
               searched_total_s / exhaustive_total_s,
               quantile(searched_cpu_s, 0.5), quantile(exhaustive_cpu_s, 0.5), baseline_differs);
  }
  fmt::print("localisation_success_rate_retrying {:.3f} ({} of {} found within {:.0f} s of the start, trying again as aditd does)\n",
             rate_retrying, found_retrying, starts.size(), o.retry_s);
  fmt::print("false_localisations_retrying {}\n", wrong_retrying);
  fmt::print("time_to_localise_s median {:.2f} (max {:.2f}; sensor time to the found try's result, its CPU included)\n",
             median_time_s, max_time_s);
  if (!err_m.empty())
    fmt::print("error of the localised: median {:.3f} m {:.3f} deg, max {:.3f} m {:.3f} deg\n", quantile(err_m, 0.5),
               quantile(err_deg, 0.5), *std::max_element(err_m.begin(), err_m.end()),
               *std::max_element(err_deg.begin(), err_deg.end()));
  if (!drift) {
    fmt::print("drift_percent_with_prior not measured (--no-drift)\ndrift_percent_without_prior not measured\n");
    return kExitOk;
  }
  const DriftRun& with = drift->with_prior;
  const DriftRun& without = drift->without_prior;
  if (with.anchored)
    fmt::print("odometry anchored to the prior after {:.1f} s ({} localisation tries)\n", with.anchored_at_s,
               with.localisation_tries);
  else
    fmt::print("odometry never localised against the prior ({} tries; last: {})\n", with.localisation_tries, with.failure);
  const auto line = [](const char* what, const DriftRun& r) {
    fmt::print("{}: end {:.3f} m over {:.1f} m; APE rms {:.3f} m, max {:.3f} m {:.2f} deg (rms {:.3f} m after a rigid "
               "fit); odometry median {:.2f} ms, p99 {:.2f} ms per scan; {} invalid\n",
               what, r.end_error_m, r.path_m, r.ape_rms_m, r.ape_max_m, r.ape_max_deg, r.ape_fitted_rms_m, r.odometry_median_ms,
               r.odometry_p99_ms, r.invalid_poses);
  };
  if (with.anchored) {
    fmt::print("drift_percent_with_prior {:.4f}\n", with.drift_percent);
  } else {
    fmt::print("drift_percent_with_prior not measured (not localised)\n");
  }
  fmt::print("drift_percent_without_prior {:.4f}\n", without.drift_percent);
  line("with the prior", with);
  line("without the prior", without);
  return kExitOk;
}

}  // namespace

void add_bench_prior_map_command(CLI::App& bench, int& status) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = bench.add_subcommand("prior-map", "Global localisation against a prior map from random starts of a simulated session");
  cmd->add_option("--session", o->session, "Simulated session folder (adit sim)")->required();
  cmd->add_option("--prior", o->prior, "Prior map: a prepared folder, or a cloud/mesh file (default: the session's bim.ply)");
  cmd->add_option("--prior-trajectory", o->prior_trajectory,
                  "When the prior is another session's map: that session's trajectory.tum (the prior's frame) ...");
  cmd->add_option("--prior-truth", o->prior_truth, "... and its truth_body.tum, which place the prior in the world");
  cmd->add_option("--starts", o->starts, "Random starts")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--scans", o->scans, "Scans accumulated per start")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the starts")->capture_default_str();
  cmd->add_option("--hint-m", o->hint_m, "Give a hint up to this far off (heading within 10 deg); 0: none")->capture_default_str();
  cmd->add_option("--tilt-sigma-deg", o->tilt_sigma_deg, "σ of the levelling error")->capture_default_str();
  cmd->add_option("--retry-s", o->retry_s,
                  "After a failed try, try again as aditd does for this long from the start (sensor time); 0: one try")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("!--no-confirm", o->confirm,
                "Take the first found try, as aditd with prior_map.confirm: false (default: once the next found one agrees)");
  cmd->add_option("--min-overlap", o->min_overlap,
                  "The acceptance's overlap threshold (0: slam::LocalisationConfig's default)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_flag("--json", o->json, "Print the figures as JSON");
  cmd->add_option("--search-levels", o->search_levels,
                  "The plan search's branch-and-bound depth (0: every plan cell scored; default: slam's)")
      ->check(CLI::Range(0, 12));
  cmd->add_flag("--exhaustive-baseline", o->exhaustive_baseline,
                "Search each try again with every plan cell scored: the CPU ratio, and whether any result differs");
  cmd->add_option("--prior-sigma-m", o->prior_sigma_m,
                  "σ of a residual against the prior in the anchored odometry (0: the odometry's default)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--prior-stride", o->prior_stride,
                  "Every Nth registration point looks up the prior in the anchored odometry (0: the odometry's default)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("!--no-drift", o->drift, "Skip the odometry with and without the prior (drift_percent_*)");
  cmd->callback([o, &status] {
    if (o->prior_trajectory.empty() != o->prior_truth.empty())
      throw InputError("", "--prior-trajectory/--prior-truth", "give both or neither");
    status = run(*o);
  });
}

}  // namespace adit::tools
