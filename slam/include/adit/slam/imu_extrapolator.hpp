#pragma once
// The body's pose at the IMU's rate between scans, for a flight controller:
// the LiDAR-inertial filter's state after the latest scan (its anchor)
// carried forward through every IMU reading received since, by the filter's
// own kinematics (a forward prediction, as FAST-LIO2 and DLIO publish between
// scans; Xu et al. 2022 §IV-B, Chen et al. 2023 §III-B), and the filter's
// covariance with it: a flight controller weighs the pose by it, and it grows
// with the time since the scan.
//
// A new anchor is older than the newest readings (the scan was being
// registered meanwhile): the readings since its time are integrated again
// from it, so each scan's correction reaches the high-rate pose at once.
// Nothing is extrapolated without an anchor, across a gap in the readings,
// or further than `max_horizon_s` past the anchor (the LiDAR stopped or the
// odometry fell behind: dead reckoning on a MEMS IMU is metres off within
// seconds, and no pose is better than a confident wrong one).
//
// Preallocated: no allocation after construction.

#include <cstddef>
#include <optional>
#include <vector>

#include "adit/slam/imu_sample.hpp"
#include "adit/slam/inertial_filter.hpp"

namespace adit::slam {

struct ImuExtrapolatorConfig {
  // The odometry filter's: its noise, lever arm and largest gap between readings.
  InertialConfig inertial;
  double max_horizon_s = 0.5;   // how far past the anchor a pose is given
  std::size_t capacity = 1024;  // readings kept to re-integrate from a late anchor (2.5 s at 400 Hz)
};

class ImuExtrapolator {
 public:
  explicit ImuExtrapolator(const ImuExtrapolatorConfig& config);

  // The filter's state and covariance after a scan (InertialFilter::state(), covariance()).
  void anchor(const InertialState& state, const Matrix18d& covariance = Matrix18d::Zero());
  // One more body-frame reading with a gyroscope, ascending in t: the state
  // at its time, or none (no anchor, a gap, past the horizon, out of order).
  std::optional<InertialState> add(const ImuSample& reading);
  // The pose's covariance at the last state add() gave, in the body tangent
  // [ρ; δθ] as the scan-rate pose's (pose_t).
  Matrix6d pose_covariance() const;

 private:
  // Carries current_ from its time to `to`'s, reading `from` before it.
  void step(const ImuSample& from, const ImuSample& to);
  const ImuSample& kept(std::size_t i) const { return ring_[(head_ + i) % ring_.size()]; }

  ImuExtrapolatorConfig config_;
  std::vector<ImuSample> ring_;  // the newest `count_` readings from head_
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  std::optional<double> anchor_t_;  // the latest anchor's time
  InertialState current_;
  Matrix18d covariance_ = Matrix18d::Zero();  // current_'s
  bool current_valid_ = false;  // current_ follows the anchor through every reading since
};

}  // namespace adit::slam
