#include "adit/eval/pose_error.hpp"

#include <cmath>

namespace adit::eval {

double rotation_angle(const Eigen::Matrix3d& r) {
  const Eigen::Vector3d axis(r(2, 1) - r(1, 2), r(0, 2) - r(2, 0), r(1, 0) - r(0, 1));
  return std::atan2(0.5 * axis.norm(), 0.5 * (r.trace() - 1.0));
}

}  // namespace adit::eval
