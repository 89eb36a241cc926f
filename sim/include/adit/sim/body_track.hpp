#pragma once
// A platform's body trajectory, sampled densely (kRate) and interpolated
// (position linearly, orientation by slerp) at any instant, so every LiDAR
// firing is cast from the pose at its own time.

#include <vector>

#include <Eigen/Geometry>

namespace adit::sim {

struct BodySample {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  double speed_mps = 0.0;     // forward speed in the body frame (wheels)
  double yaw_rate_rps = 0.0;  // about the body z axis (wheels)
};

class BodyTrack {
 public:
  static constexpr double kRate = 200.0;  // samples per second

  explicit BodyTrack(std::vector<BodySample> samples);
  // Seconds since the start; clamped to [0, duration()].
  Eigen::Isometry3d pose(double t) const;
  double duration() const { return duration_; }
  const std::vector<BodySample>& samples() const { return samples_; }

 private:
  std::vector<BodySample> samples_;
  double duration_ = 0.0;
};

}  // namespace adit::sim
