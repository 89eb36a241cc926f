#pragma once
// A planar pose (x, y, heading), for ground robots' wheel odometry.

#include <cmath>
#include <numbers>

namespace adit::slam {

struct Pose2 {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;  // radians, counter-clockwise from +x, kept in (-pi, pi]
};

inline double wrap_angle(double a) {
  a = std::remainder(a, 2.0 * std::numbers::pi);
  return a <= -std::numbers::pi ? a + 2.0 * std::numbers::pi : a;
}

}  // namespace adit::slam
