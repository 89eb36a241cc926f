#pragma once
// The start search of Odometry (docs/decisions/012-start-search.md): with no
// velocity known, the registration is also started from offsets along the
// body's x and y axes, every `step_m` up to `reach_m`, nearest first, and an
// offset's result replaces the best one when it explains clearly more of the
// scan (`margin` more correspondences). Shared by the LiDAR-only step
// (odometry.cpp) and the LiDAR-inertial one (odometry_inertial.cpp).

#include <cmath>

#include <Eigen/Core>

#include "adit/slam/registration.hpp"

namespace adit::slam {

// `register_from(offset)` registers from the prediction moved by `offset`
// (m, body x and y) and returns the result.
template <typename RegisterFrom>
void search_start(double reach_m, double step_m, double margin, RegisterFrom&& register_from, RegistrationResult& best) {
  const auto steps = static_cast<int>(std::floor(reach_m / step_m + 1e-9));
  for (int k = 1; k <= steps; ++k) {
    const double d = k * step_m;
    for (const Eigen::Vector2d& offset :
         {Eigen::Vector2d(d, 0.0), Eigen::Vector2d(-d, 0.0), Eigen::Vector2d(0.0, d), Eigen::Vector2d(0.0, -d)}) {
      const RegistrationResult alternative = register_from(offset);
      if (static_cast<double>(alternative.correspondences) > (1.0 + margin) * static_cast<double>(best.correspondences))
        best = alternative;
    }
  }
}

}  // namespace adit::slam
