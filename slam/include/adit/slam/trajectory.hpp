#pragma once
// A trajectory: poses of a body in a fixed frame, each with a time stamp.
// Evaluation, odometry output and file readers all share this value type.

#include <cstddef>
#include <vector>

#include <Eigen/Geometry>

namespace adit::slam {

// Body-to-world rigid transform.
using Pose = Eigen::Isometry3d;

struct Trajectory {
  std::vector<double> stamps;  // seconds, non-decreasing; frame indices when !timed
  std::vector<Pose> poses;     // same length as stamps
  bool timed = true;           // false when the source had no times (KITTI without a times file)

  std::size_t size() const { return poses.size(); }
  bool empty() const { return poses.empty(); }
  void reserve(std::size_t n) {
    stamps.reserve(n);
    poses.reserve(n);
  }
  void push_back(double stamp, const Pose& pose) {
    stamps.push_back(stamp);
    poses.push_back(pose);
  }
};

}  // namespace adit::slam
