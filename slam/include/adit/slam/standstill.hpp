#pragma once
// Standstill: whether a registered scan shows the body at rest, so that the
// LiDAR-inertial filter may take a zero-velocity update (ZUPT; Foxlin 2005,
// "Pedestrian tracking with shoe-mounted inertial sensors", and Skog et al.
// 2010, "Zero-velocity detection — an algorithm evaluation", for the update
// in an inertial navigator).
//
// Why: along a direction the scan cannot see (a drift's axis, a drone on
// the floor of a tunnel) the filter's velocity is the integral of the
// accelerometer's error, and the map taken meanwhile is smeared along that
// axis (docs/decisions/039-zero-velocity-update.md).
//
// The test: every direction the scan does see is still between two scans,
// the IMU felt no acceleration over the interval, and the filter's speed is
// low. The scan alone cannot see its degenerate axis, and the accelerometer
// alone cannot tell rest from a steady glide; together they leave only a
// body gliding slowly along exactly that axis, without turning or
// accelerating, which the speed gate keeps small.

#include <Eigen/Geometry>

#include "adit/slam/registration.hpp"

namespace adit::slam {

struct StandstillConfig {
  bool enabled = true;
  double max_speed_mps = 0.03;        // translation the scan sees, per second between scans
  double max_rate_radps = 0.02;       // rotation the scan sees (1.1°/s)
  double max_filter_speed_mps = 0.2;  // the filter's own speed, before the update
  // What the IMU felt between the scans: the filter's velocity change over
  // the interval (the accelerometer's mean, gravity and bias removed; a
  // rotor's vibration averages out). A body setting off is not still yet.
  double max_acceleration_mps2 = 0.2;
  double velocity_sigma_mps = 0.01;   // σ of the zero velocity, per axis
};

// Whether the body appears still from `from` (the previous scan's pose) to
// `registration.pose` over `dt` s, with `velocity` (world, m/s) the
// filter's before the update and `velocity_change` what its propagation over
// the interval added. A degenerate registration's weakest direction
// is left out: there its pose is the prediction's, not the scan's.
bool appears_still(const Eigen::Isometry3d& from, const RegistrationResult& registration, double dt,
                   const Eigen::Vector3d& velocity, const Eigen::Vector3d& velocity_change,
                   const StandstillConfig& config);

}  // namespace adit::slam
