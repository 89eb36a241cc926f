// Naming and copying an IMU stream's counts, on slow threads (imu_stats.hpp).
#include "adit/daemon/imu_stats.hpp"

#include <fmt/format.h>

#include "adit/config/config.hpp"

namespace adit::daemon {

std::string_view to_string(ImuProblem problem) {
  switch (problem) {
    case ImuProblem::gap: return "gap";
    case ImuProblem::saturated: return "saturated";
    case ImuProblem::stuck_axis: return "stuck axis";
    case ImuProblem::time_back: return "time going back";
    case ImuProblem::undecodable: return "undecodable";
    case ImuProblem::unpaired: return "unpaired";
    case ImuProblem::unclocked: return "off the LiDAR clock";
  }
  return "?";
}

std::string_view imu_source_name(config::ImuSource source) {
  switch (source) {
    case config::ImuSource::ouster: return "ouster";
    case config::ImuSource::livox: return "livox";
    case config::ImuSource::can: break;
  }
  return "can";
}

std::string describe_problems(const ImuStats& s, std::string_view source) {
  std::string text;
  for (std::size_t k = 0; k < kImuProblemKinds; ++k) {
    const auto problem = static_cast<ImuProblem>(k);
    const std::uint64_t n = s.count(problem);
    if (n == 0) continue;
    text += fmt::format("{}{} {}", text.empty() ? "" : ", ", n, to_string(problem));
    if (problem == ImuProblem::gap) text += fmt::format(" (longest {:.3f} s)", s.longest_gap_s.load());
  }
  if (text.empty()) return text;
  static constexpr std::string_view kAxes[6] = {"ax", "ay", "az", "gx", "gy", "gz"};
  const int last = s.last_problem.load();
  const int axis = s.last_problem_axis.load();
  std::string where = fmt::format("{} {}", source == "can" ? "frame" : "packet", s.last_problem_packet.load());
  if (axis >= 0 && axis < 6) where = fmt::format("axis {} at {}", kAxes[axis], where);
  return fmt::format("IMU {}: {}; last: {} at {}", source, text,
                     last >= 0 ? to_string(static_cast<ImuProblem>(last)) : "?", where);
}

void copy_stats(const ImuStats& from, ImuStats& to) {
  constexpr auto r = std::memory_order_relaxed;
  to.packets.store(from.packets.load(r), r);
  to.samples.store(from.samples.load(r), r);
  to.gyro_samples.store(from.gyro_samples.load(r), r);
  to.dropped.store(from.dropped.load(r), r);
  to.rate_hz.store(from.rate_hz.load(r), r);
  to.longest_gap_s.store(from.longest_gap_s.load(r), r);
  to.last_t.store(from.last_t.load(r), r);
  to.last_seen_realtime_ns.store(from.last_seen_realtime_ns.load(r), r);
  to.time_offset_s.store(from.time_offset_s.load(r), r);
  to.clock_spread_s.store(from.clock_spread_s.load(r), r);
  for (std::size_t k = 0; k < kImuProblemKinds; ++k) to.problems[k].store(from.problems[k].load(r), r);
  to.last_problem_packet.store(from.last_problem_packet.load(r), r);
  to.last_problem_axis.store(from.last_problem_axis.load(r), r);
  to.last_problem.store(from.last_problem.load(r), r);
}

}  // namespace adit::daemon
