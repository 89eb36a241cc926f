#pragma once
// The KITTI odometry benchmark's drift measure (Geiger et al., "Are we ready
// for autonomous driving?", CVPR 2012; devkit evaluate_odometry.cpp): from
// every 10th frame, for each length L in 100, 200, ..., 800 m of reference
// path, the first frame j whose path distance exceeds L; the error
// E = (P_i^-1 P_j)^-1 (Q_i^-1 Q_j) gives |trans(E)| / L and angle(rot(E)) / L.
// Reported as the mean over all segments, in % and degrees per 100 m.

#include <array>
#include <cstddef>
#include <optional>
#include <span>

#include "adit/slam/trajectory.hpp"

namespace adit::eval {

inline constexpr std::array<double, 8> kKittiLengths{100, 200, 300, 400, 500, 600, 700, 800};
inline constexpr std::size_t kKittiStep = 10;

struct KittiLengthDrift {
  double length = 0.0;
  std::size_t segments = 0;
  double translation_percent = 0.0;
  double rotation_deg_per_100m = 0.0;
};

struct KittiDrift {
  std::size_t segments = 0;
  double translation_percent = 0.0;    // mean over segments of 100 |trans(E)| / L
  double rotation_deg_per_100m = 0.0;  // mean over segments of 100 angle(E) / L, degrees
  std::array<KittiLengthDrift, kKittiLengths.size()> by_length{};
};

// ref and est are matched pose by pose. nullopt when the reference path is
// shorter than 100 m (no segment).
std::optional<KittiDrift> kitti_drift(std::span<const slam::Pose> ref, std::span<const slam::Pose> est);

}  // namespace adit::eval
