#pragma once
// Calibrating wheel odometry against a reference trajectory (GNSS/INS now,
// LiDAR odometry later): left and right wheel travel scales (effective radii),
// the effective track width, and the time offset between the encoders and the
// reference. Pure.
//
// The drive is cut into windows of a fixed duration. For each window the
// reference gives a path length d and a heading change dpsi (heading from the
// direction of motion, so the reference needs no orientation); the wheels
// give travels L, R over the same window shifted by the time offset tau:
//   r_d   = (s_l L + s_r R) / 2 - d                 (m)
//   r_psi = wrap((s_r R - s_l L) / b - dpsi)        (rad)
// Each divided by its sigma, and minimised in least squares with
// Levenberg-Marquardt (Nocedal & Wright, "Numerical Optimization", 2nd ed.,
// §10.3) and central-difference Jacobians. This is the classic "UMBmark"
// idea of separating scale and track errors (Borenstein & Feng, IEEE T-RA
// 1996) with a continuous reference in place of the square path.

#include <cstddef>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "adit/slam/pose2.hpp"
#include "adit/slam/wheel_odometry.hpp"

namespace adit::eval {

struct WheelSpeedSample {
  double t = 0.0;      // s, encoder clock
  double left = 0.0;   // m/s at the rim, before calibration scales
  double right = 0.0;  // m/s
};

struct PlanarPosition {
  double t = 0.0;  // s, reference clock
  double x = 0.0;  // m (east)
  double y = 0.0;  // m (north)
};

struct CalibrationOptions {
  slam::WheelGeometry nominal;          // starting values: left/right_scale, effective_track()
  double window = 1.0;            // s per residual window
  double heading_span = 0.5;      // s: the reference heading is the chord's direction over this span
  double min_speed = 1.0;         // m/s: slower windows are skipped (heading undefined)
  double max_time_offset = 1.0;   // s: windows keep this margin to the data's ends
  double sigma_distance = 0.05;   // m per window
  double sigma_heading = 0.005;   // rad per window
  bool separate_scales = true;    // fit left and right scales (else one common scale)
  bool fit_time_offset = true;
  unsigned max_iterations = 50;
};

struct CalibrationResult {
  double left_scale = 1.0;
  double right_scale = 1.0;
  double effective_track = 0.0;  // m
  double time_offset = 0.0;      // s: reference time = encoder time + time_offset
  Eigen::Vector4d standard_deviation = Eigen::Vector4d::Zero();  // of the four above (0 when not fitted)

  std::size_t windows = 0;
  unsigned iterations = 0;
  bool converged = false;
  double rms_distance_before = 0.0;  // m per window, nominal parameters
  double rms_distance_after = 0.0;
  double rms_heading_before = 0.0;  // rad per window
  double rms_heading_after = 0.0;

  // Dead reckoning over the whole reference span, started at the reference's
  // first position and heading: distance of the end from the reference's end.
  double endpoint_error_before = 0.0;  // m
  double endpoint_error_after = 0.0;
  double reference_length = 0.0;  // m, planar path length over that span
  double wheel_length_before = 0.0;
  double wheel_length_after = 0.0;
};

// Throws std::invalid_argument when the data overlap too little to form windows.
CalibrationResult calibrate_wheels(std::span<const WheelSpeedSample> wheels, std::span<const PlanarPosition> reference,
                                   const CalibrationOptions& options);

// Wheel dead reckoning from `start` over reference times [t0, t1] (encoder
// samples shifted by time_offset), returning the poses at each sample.
// Samples whose time does not increase are skipped; throws
// std::invalid_argument when fewer than two remain.
std::vector<slam::Pose2> dead_reckon(std::span<const WheelSpeedSample> wheels, double left_scale, double right_scale,
                               double effective_track, double time_offset, const slam::Pose2& start, double t0, double t1);

// Planar path length of the reference between t0 and t1.
double path_length(std::span<const PlanarPosition> reference, double t0, double t1);

}  // namespace adit::eval
