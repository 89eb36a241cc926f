#pragma once
// Gravity's direction from an accelerometer, the odometry's tilt reference
// (its σ is the config's imu.gravity_sigma_deg). An accelerometer measures specific
// force f = a − g in its own axes: the body's kinematic acceleration a minus
// gravity g = (0, 0, −9.81 m/s²) in a z-up world. Averaged over a sweep and
// with the kinematic part removed, f̄ − ā = −g: a vector of 9.81 m/s² along
// the world's up, seen in the body frame. What is left in it (bias, noise,
// the part of ā nobody measured) tilts that up by its share of 9.81 m/s²:
// 1 mg of error is 0.06°.

#include <optional>

#include <Eigen/Core>

namespace adit::slam {

inline constexpr double kStandardGravity = 9.80665;  // m/s², CGPM 1901

// Gravity's up in the body frame (unit) and how far it may be off (rad).
struct UpMeasurement {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  double sigma_rad = 0.0;
};

// What is left of the kinematic acceleration after removing an estimate of
// it, as a share of it: the wheels' acceleration over a sweep is a difference
// of two speeds, each a difference of positions, so it lags and scales with
// the wheels' errors. Measured on the simulated drift's start (0.75 m/s²):
// 0.06 m/s² of difference between the accelerometer and the wheels, 8 %.
inline constexpr double kAccelerationResidualShare = 0.1;

// The up vector from the mean specific force and the mean kinematic
// acceleration over the same interval (both body frame, m/s²). Its σ is
// `sigma_rad` (the accelerometer's own error: noise, bias) and
// kAccelerationResidualShare of the horizontal acceleration's tilt, added in
// quadrature. nullopt when the difference is not gravity-sized (more than
// `tolerance` of g away from it: a shock, a fall, a broken sensor), so a
// wrong reading cannot tilt the map.
std::optional<UpMeasurement> measured_up(const Eigen::Vector3d& mean_specific_force,
                                         const Eigen::Vector3d& mean_acceleration, double sigma_rad,
                                         double tolerance = 0.05);

}  // namespace adit::slam
