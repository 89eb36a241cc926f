#include "adit/slam/standstill.hpp"

#include "adit/slam/lie.hpp"

namespace adit::slam {

bool appears_still(const Eigen::Isometry3d& from, const RegistrationResult& registration, double dt,
                   const Eigen::Vector3d& velocity, const Eigen::Vector3d& velocity_change,
                   const StandstillConfig& config) {
  if (!config.enabled || !(dt > 0.0) || velocity.norm() > config.max_filter_speed_mps ||
      velocity_change.norm() > config.max_acceleration_mps2 * dt)
    return false;
  Vector6d motion = log_se3(from.inverse() * registration.pose);  // body twist [ρ; φ]
  if (registration.degenerate) {
    const Vector6d& weakest = registration.weakest_direction;  // unit, in one block (registration.cpp)
    motion -= weakest * weakest.dot(motion);
  }
  return motion.head<3>().norm() <= config.max_speed_mps * dt && motion.tail<3>().norm() <= config.max_rate_radps * dt;
}

}  // namespace adit::slam
