#pragma once
// The checks every IMU reading passes before the odometry sees it, whichever
// source it came from: time must advance (a reading at or before the previous
// one is dropped), and gaps, saturated axes and stuck axes are counted by
// name (ImuStats) but the reading is kept: the odometry decides what to trust.
// The rate is measured from the readings' own stamps. One thread (the one
// that reads the IMU) calls check(); no allocation, lock or log.

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "adit/daemon/imu_stats.hpp"
#include "adit/slam/motion_history.hpp"

namespace adit::daemon {

// Where an axis saturates: readings with |value| ≥ the limit (or at the
// encoding's lowest or highest value) are saturated. 0 = no limit.
struct ImuLimits {
  double accel_mps2 = 0.0;
  double gyro_radps = 0.0;
};

class ImuMonitor {
 public:
  // A gap: more than this many nominal periods between two readings.
  static constexpr double kGapPeriods = 3.0;
  // A stuck axis: the same value this many readings in a row (1 s at 100 Hz;
  // a MEMS unit's noise moves every axis by several of its steps per reading).
  static constexpr int kStuckReadings = 100;

  ImuMonitor(ImuStats& stats, ImuLimits limits) : stats_(stats), limits_(limits) {}

  // Counts and names the reading's problems; false when it must be dropped
  // (time going back). `packet` numbers the packet or frame for the report;
  // `saturated_axes` has bit i set for an axis (ax ay az gx gy gz) the source
  // found at its encoding's limit; readings are in the IMU's own axes.
  bool check(const slam::ImuSample& reading, std::uint64_t packet, unsigned saturated_axes = 0);
  // A problem found by the source itself (undecodable, unpaired, unclocked).
  void report(ImuProblem problem, std::uint64_t packet, int axis = -1);

 private:
  ImuStats& stats_;
  ImuLimits limits_;
  bool first_ = true;
  double previous_t_ = 0.0;
  double period_s_ = 0.0;  // the running mean period, gaps left out
  std::uint64_t periods_ = 0;
  std::array<double, 6> last_value_{};
  std::array<int, 6> same_count_{};
};

}  // namespace adit::daemon
