// adit eval loops: loop detection of an aditd session against the simulator's
// truth (eval/loop_truth.hpp defines every figure; docs/LOOPS.md "Measured").

#include <algorithm>
#include <filesystem>
#include <string>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/eval/loop_summary_io.hpp"
#include "adit/eval/loop_truth.hpp"
#include "adit/eval/trajectory_io.hpp"
#include "eval_commands.hpp"

namespace adit::tools {
namespace {

nlohmann::json optional_json(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); }

std::string percent(const std::optional<double>& v) { return v ? fmt::format("{:.1f} %", 100.0 * *v) : "n/a"; }

}  // namespace

void run_eval_loops(const LoopsEvalOptions& o) {
  const std::filesystem::path dir(o.session);
  const std::filesystem::path summary = dir / "summary.json", keyframes_file = dir / "keyframes.tum";
  if (!std::filesystem::exists(summary)) throw InputError(summary.string(), "", "missing (not an aditd session folder?)");
  if (!std::filesystem::exists(keyframes_file)) throw InputError(keyframes_file.string(), "", "missing");
  const std::vector<eval::LoopEdgeRecord> loops = eval::read_loop_edges(summary);
  const slam::Trajectory keyframes = eval::read_tum(keyframes_file);
  const slam::Trajectory truth = eval::read_tum(o.truth);
  const eval::KeyframeTruth at_keyframes = eval::keyframe_truth(truth, keyframes.stamps, o.truth);
  const eval::LoopTruthConfig& c = o.judge;
  const eval::LoopTruthReport r = eval::evaluate_loops(at_keyframes, loops, c, summary.string());
  const std::size_t partial = static_cast<std::size_t>(
      std::count_if(r.loops.begin(), r.loops.end(), [](const eval::LoopCheck& l) { return l.partial; }));
  if (o.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const eval::LoopCheck& l : r.loops)
      list.push_back({{"from", l.loop.from}, {"to", l.loop.to}, {"partial", l.partial},
                      {"truth_distance_m", l.truth_distance_m}, {"truth_path_m", l.truth_path_m},
                      {"error_m", l.error_m}, {"error_judged_m", l.error_judged_m}, {"error_deg", l.error_deg},
                      {"false", l.is_false}});
    nlohmann::json stretches = nlohmann::json::array();
    for (const eval::Stretch& s : r.revisit_stretches) stretches.push_back({s.first, s.last});
    const nlohmann::json j{
        {"session", o.session},
        {"truth", o.truth},
        {"settings", {{"revisit_m", c.revisit_m}, {"min_path_m", c.min_path_m}, {"false_beyond_m", c.false_beyond_m},
                      {"max_error_m", c.max_error_m}, {"max_error_deg", c.max_error_deg}, {"window", c.window}}},
        {"keyframes", r.keyframes},
        {"revisit_keyframes", r.revisit_keyframes.size()},
        {"revisit_stretches", stretches},
        {"recalled_keyframes", r.recalled_keyframes},
        {"recalled_stretches", r.recalled_stretches},
        {"accepted", r.loops.size()},
        {"accepted_partial", partial},
        {"false_accepted", r.false_loops},
        {"precision", optional_json(r.precision)},
        {"recall", optional_json(r.recall)},
        {"error_m", stats_json(r.error_m)},
        {"error_deg", stats_json(r.error_deg)},
        {"loops", list}};
    fmt::print("{}\n", j.dump(2));
    return;
  }
  fmt::print("session            {} ({} keyframes)\n", o.session, r.keyframes);
  fmt::print("true revisits      {} keyframes in {} stretches (within {:.1f} m, >= {:.0f} m back along the path)\n",
             r.revisit_keyframes.size(), r.revisit_stretches.size(), c.revisit_m, c.min_path_m);
  fmt::print("accepted loops     {} ({} partial)\n", r.loops.size(), partial);
  fmt::print("false accepted     {} (> {:.1f} m apart, or off the truth by > {:.2f} m / {:.1f} deg)\n", r.false_loops,
             c.false_beyond_m, c.max_error_m, c.max_error_deg);
  fmt::print("precision          {}\n", percent(r.precision));
  fmt::print("recall             {} ({} of {} revisit keyframes with a true loop within +-{} keyframes; {} of {} stretches)\n",
             percent(r.recall), r.recalled_keyframes, r.revisit_keyframes.size(), c.window, r.recalled_stretches,
             r.revisit_stretches.size());
  fmt::print("{}", stats_header());
  fmt::print("{}", stats_row("true loops' error (m)", r.error_m));
  fmt::print("{}", stats_row("true loops' error (deg)", r.error_deg));
  if (!r.loops.empty()) fmt::print("{:>6} {:>6} {:>8} {:>10} {:>9} {:>9} {:>9} {:>6}\n", "from", "to", "partial",
                                   "truth (m)", "path (m)", "err (m)", "err (deg)", "false");
  for (const eval::LoopCheck& l : r.loops)
    fmt::print("{:>6} {:>6} {:>8} {:>10.3f} {:>9.1f} {:>9.4f} {:>9.3f} {:>6}\n", l.loop.from, l.loop.to,
               l.partial ? "yes" : "no", l.truth_distance_m, l.truth_path_m, l.error_judged_m, l.error_deg,
               l.is_false ? "FALSE" : "");
}

}  // namespace adit::tools
