#pragma once
// The recent motion sensor samples the odometry asks about between two scans:
// the wheels' integrated planar pose (for the motion prior and the body's
// kinematic acceleration) and the accelerometer's specific force (for
// gravity's direction). Fixed capacity, oldest dropped, no allocation after
// construction; one thread (the odometry's) pushes and reads.

#include <algorithm>
#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "adit/slam/imu_sample.hpp"
#include "adit/slam/odometry.hpp"
#include "adit/slam/pose2.hpp"

namespace adit::slam {

struct WheelSample {
  double t = 0.0;         // s, on the LiDAR clock (wheel_odometry.time_offset_s removed)
  Pose2 pose;             // integrated body pose
  double distance = 0.0;  // m travelled so far
  // The wheels were silent before this sample (a bus-off, a cable: longer
  // than WheelLimits::max_gap): how the body moved since the sample before is
  // not known, so no prior is interpolated across it.
  bool after_gap = false;
  // A wheel was held over this sample's interval (slip, or a reading no
  // vehicle can give: WheelStep::slip, impossible): the travel integrated is
  // a guess at what the wheel would have done, which in a turn's onset can be
  // tenths of a radian off (the held wheel assumes the turn rate from before).
  bool held = false;
};

// Samples of one kind (with a time `t`): fixed capacity, the oldest dropped,
// time strictly advancing (others are ignored).
template <typename Sample>
class TimedRing {
 public:
  explicit TimedRing(std::size_t capacity) : ring_(std::max<std::size_t>(capacity, 2)) {}
  void push(const Sample& sample) {
    if (size_ > 0 && !(sample.t > back().t)) return;
    if (size_ == ring_.size()) {
      first_ = (first_ + 1) % ring_.size();
      --size_;
    }
    ring_[(first_ + size_) % ring_.size()] = sample;
    ++size_;
  }
  std::size_t size() const { return size_; }
  // Oldest first; i < size().
  const Sample& operator[](std::size_t i) const { return ring_[(first_ + i) % ring_.size()]; }
  const Sample& back() const { return (*this)[size_ - 1]; }
  // Time of the newest sample; -infinity when empty.
  double latest() const { return size_ == 0 ? -std::numeric_limits<double>::infinity() : back().t; }

 private:
  std::vector<Sample> ring_;
  std::size_t first_ = 0;
  std::size_t size_ = 0;
};

// Recent accelerometer readings.
class ImuHistory {
 public:
  explicit ImuHistory(std::size_t capacity) : samples_(capacity) {}
  void push(const ImuSample& sample) { samples_.push(sample); }
  double latest() const { return samples_.latest(); }
  // The mean specific force over [t0, t1], the readings joined by straight
  // lines; nullopt unless readings lie on both sides and `min_samples` within.
  std::optional<Eigen::Vector3d> mean(double t0, double t1, std::size_t min_samples = 3) const;
  // The readings from the last at or before t0 to the first at or after t1
  // (what covers [t0, t1]) into `out`, oldest first (cleared; no allocation
  // within its capacity): the odometry's ScanInput::imu.
  void copy_covering(double t0, double t1, std::vector<ImuSample>& out) const;

 private:
  TimedRing<ImuSample> samples_;
};

// Recent wheel samples.
class WheelHistory {
 public:
  explicit WheelHistory(std::size_t capacity) : samples_(capacity) {}
  void push(const WheelSample& sample) { samples_.push(sample); }
  std::size_t size() const { return samples_.size(); }
  // Oldest first; i < size().
  const WheelSample& operator[](std::size_t i) const { return samples_[i]; }
  // Time of the newest sample; -infinity when empty.
  double latest() const { return samples_.latest(); }
  // Distance travelled at the newest sample (0 when empty).
  double latest_distance() const { return samples_.size() == 0 ? 0.0 : samples_.back().distance; }
  // The body motion from t0 to t1 by the wheels (interpolated,
  // slam/wheel_prior.hpp), nullopt when the samples do not cover [t0, t1],
  // the wheels were silent in between, or a wheel was held (held()).
  std::optional<MotionPrior> prior(double t0, double t1) const;
  // A sample whose interval overlaps (t0, t1] was held: its motion is a guess.
  bool held(double t0, double t1) const;
  // The body's mean kinematic acceleration over [t0, t1] in the body frame
  // (x forward, y left), as a planar vehicle on its wheels moves: the change
  // of forward speed over the interval, v(t1) − v(t0) over t1 − t0, plus the
  // centripetal ω·v to the left (ω × v). The speeds are central differences
  // over ±`half_window` s; nullopt when the samples do not cover that or a
  // wheel was held within it.
  std::optional<Eigen::Vector3d> acceleration(double t0, double t1, double half_window = 0.05) const;

 private:
  bool interpolate(double t, Pose2& pose, double& distance) const;
  TimedRing<WheelSample> samples_;
};

}  // namespace adit::slam
