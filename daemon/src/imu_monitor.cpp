// The per-reading checks of an IMU stream; counts only, no allocation or log
// (imu_monitor.hpp).
#include "adit/daemon/imu_monitor.hpp"

#include <algorithm>
#include <cmath>

namespace adit::daemon {

void ImuMonitor::report(ImuProblem problem, std::uint64_t packet, int axis) {
  stats_.problems[static_cast<std::size_t>(problem)].fetch_add(1, std::memory_order_relaxed);
  stats_.last_problem_packet.store(packet, std::memory_order_relaxed);
  stats_.last_problem_axis.store(axis, std::memory_order_relaxed);
  stats_.last_problem.store(static_cast<int>(problem), std::memory_order_relaxed);
}

bool ImuMonitor::check(const slam::ImuSample& r, std::uint64_t packet, unsigned saturated_axes) {
  if (!first_) {
    const double dt = r.t - previous_t_;
    if (!(dt > 0.0)) {  // NaN stamps fail here too
      report(ImuProblem::time_back, packet);
      return false;
    }
    if (periods_ >= 2 && dt > kGapPeriods * period_s_) {
      report(ImuProblem::gap, packet);
      stats_.longest_gap_s.store(std::max(stats_.longest_gap_s.load(std::memory_order_relaxed), dt),
                                 std::memory_order_relaxed);
    } else {
      // The running mean of the periods; the first few set it.
      ++periods_;
      period_s_ += (dt - period_s_) / static_cast<double>(std::min<std::uint64_t>(periods_, 100));
      stats_.rate_hz.store(1.0 / period_s_, std::memory_order_relaxed);
    }
  } else if (!std::isfinite(r.t)) {
    report(ImuProblem::time_back, packet);
    return false;
  }
  first_ = false;
  previous_t_ = r.t;
  stats_.last_t.store(r.t, std::memory_order_relaxed);

  const int axes = r.has_gyro ? 6 : 3;
  bool saturated = false;
  int saturated_axis = -1;
  for (int a = 0; a < axes; ++a) {
    const double v = a < 3 ? r.specific_force[a] : r.angular_rate[a - 3];
    const double limit = a < 3 ? limits_.accel_mps2 : limits_.gyro_radps;
    if ((saturated_axes >> a & 1U) != 0 || (limit > 0.0 && std::abs(v) >= limit) || !std::isfinite(v)) {
      saturated = true;
      saturated_axis = a;
    }
    const auto i = static_cast<std::size_t>(a);
    same_count_[i] = v == last_value_[i] ? same_count_[i] + 1 : 1;
    last_value_[i] = v;
    if (same_count_[i] == kStuckReadings) report(ImuProblem::stuck_axis, packet, a);  // once per run of equal values
  }
  if (saturated) report(ImuProblem::saturated, packet, saturated_axis);
  return true;
}

}  // namespace adit::daemon
