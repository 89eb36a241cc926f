#pragma once
// The body's pose at the IMU's rate between scans, for a flight controller:
// the LiDAR-inertial filter's state after the latest scan (its anchor)
// carried forward through every IMU reading received since, by the filter's
// own nominal kinematics (no covariance: a forward prediction, as FAST-LIO2
// and DLIO publish between scans; Xu et al. 2022 §IV-B, Chen et al. 2023 §III-B).
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
  double max_sample_gap_s = 0.05;  // as InertialConfig::max_sample_gap_s
  double max_horizon_s = 0.5;      // how far past the anchor a pose is given
  Eigen::Vector3d imu_position = Eigen::Vector3d::Zero();  // the lever arm, as InertialConfig's
  std::size_t capacity = 1024;     // readings kept to re-integrate from a late anchor (2.5 s at 400 Hz)
};

class ImuExtrapolator {
 public:
  explicit ImuExtrapolator(const ImuExtrapolatorConfig& config);

  // The filter's state after a scan (InertialFilter::state()).
  void anchor(const InertialState& state);
  // One more body-frame reading with a gyroscope, ascending in t: the state
  // at its time, or none (no anchor, a gap, past the horizon, out of order).
  std::optional<InertialState> add(const ImuSample& reading);

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
  bool current_valid_ = false;  // current_ follows the anchor through every reading since
};

}  // namespace adit::slam
