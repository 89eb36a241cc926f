#pragma once
// Keyframes: a pose and a downsampled scan kept every so often along the
// path, so that a later loop-closure step can move them and rebuild the map
// from them (the map tiles are derived data). A new keyframe is due when the
// body has moved or turned enough since the last one, as in most LiDAR SLAM
// front ends (e.g. LIO-SAM's 1 m / 0.2 rad rule).

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

namespace adit::slam {

struct Keyframe {
  std::int64_t stamp_ns = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // body in the map frame
  std::vector<Eigen::Vector3f> points;                      // body frame, deskewed, downsampled
};

struct KeyframeRule {
  double distance_m = 1.0;
  double angle_deg = 10.0;
};

class KeyframeSelector {
 public:
  explicit KeyframeSelector(KeyframeRule rule) : rule_(rule) {}
  // True for the first pose and whenever `pose` is far enough from the last
  // keyframe's; the pose then becomes the last keyframe's.
  bool take(const Eigen::Isometry3d& pose);

 private:
  KeyframeRule rule_;
  std::optional<Eigen::Isometry3d> last_;
};

}  // namespace adit::slam
