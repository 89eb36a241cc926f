#include "adit/slam/gravity.hpp"

#include <cmath>

namespace adit::slam {

std::optional<UpMeasurement> measured_up(const Eigen::Vector3d& mean_specific_force,
                                         const Eigen::Vector3d& mean_acceleration, double sigma_rad, double tolerance) {
  const Eigen::Vector3d up = mean_specific_force - mean_acceleration;
  const double norm = up.norm();
  if (!std::isfinite(norm) || std::abs(norm - kStandardGravity) > tolerance * kStandardGravity) return std::nullopt;
  const double residual = kAccelerationResidualShare * mean_acceleration.head<2>().norm() / kStandardGravity;
  return UpMeasurement{up / norm, std::hypot(sigma_rad, residual)};
}

}  // namespace adit::slam
