#pragma once
// Where the LiDAR sits on a wheeled robot: the rotation and the planar lever
// arm of `lidar.extrinsics` (the sensor's pose X in the body frame), from one
// drive's LiDAR odometry (the sensor's poses S) against its wheel odometry
// (the body's planar poses B). Pure.
//
// The drive is cut into windows; over each, the body moves by B_rel and the
// sensor by S_rel, and a rigid mounting gives the hand-eye equation
// B_rel X = X S_rel (Shiu & Ahmad, IEEE T-RA 1989). The body moves in its
// plane, so:
// 1. Roll and pitch: every S_rel turns about the body's vertical axis seen
//    from the sensor, u = R_X^T e_z, so log(R_S,rel) = theta u: u is the
//    principal axis of the windows' rotation vectors (the top eigenvector of
//    sum w w^T); the wheels' turns give only its sign (a sensor hung upside
//    down is found as such), so a slipping wheel cannot tilt it. The
//    rotations are taken over long turns (a quarter turn, axis_turn): a
//    floor's bumps tilt the body by a degree over any span, which a window's
//    0.3 rad turn turns into a degree of error and a quarter turn into a
//    third. Spans whose rotation leaves the plane (a bump, a ramp: beyond
//    outlier_sigmas of the median) are dropped and u fitted again; so are,
//    for step 2, windows whose wheels turned otherwise than the sensor (a
//    slip: slip_turn_fraction).
// 2. Yaw and lever arm: with the sensor levelled (u turned onto e_z), the
//    planar part of the equation, t_B + R(theta) l = l + R(phi) t_S
//    (Censi, Franchi, Marchionni & Oriolo, "Simultaneous calibration of
//    odometry and sensor parameters for mobile robots", IEEE T-RO 29(2), 2013,
//    eq. 11), is linear in l and (cos phi, sin phi): solved so, then refined
//    by Gauss-Newton on (l_x, l_y, phi) reweighted with Cauchy's kernel, each
//    window judged against the median of windows of its kind (turning or
//    straight: wheels are worse in turns); theta is the levelled sensor's
//    turn (the LiDAR's heading is better than the wheels'). The wheels set
//    the scale, so calibrate them first (calibrate_wheels).
// With the floor seen in the scans (ground_plane.hpp), its normal replaces
// the turns' axis as u: the floor is under every scan, the turns only where
// the robot turned, and the floor's bumps average out over the scans; the
// turns' axis is still fitted and its angle to the floor's reported (a
// check: it should be within a few tenths of a degree).
// The height of the sensor is not observable from planar motion (every
// window's equation is blind to it): the floor gives the sensor's height
// above it, or it stays as measured by tape.
// Straight driving alone leaves the lever arm unobservable and turning on
// the spot alone the yaw: both are reported (observable = false) rather
// than guessed.

#include <cstddef>
#include <optional>
#include <span>

#include <Eigen/Geometry>

#include "adit/eval/ground_plane.hpp"
#include "adit/slam/motion_history.hpp"
#include "adit/slam/trajectory.hpp"

namespace adit::eval {

struct MountingOptions {
  double window = 1.0;            // s per relative motion
  double min_travel = 0.05;       // m: windows the wheels barely move in are skipped
  double min_turn_for_arm = 0.1;  // rad: windows turning at least this much observe the lever arm
  double outlier_sigmas = 3.0;
  // Roll and pitch from spans turning at least axis_turn within axis_span
  // (with fewer than three, from the windows).
  double axis_turn = 1.5707963267948966;  // rad
  double axis_span = 30.0;                // s
  // A slip: the wheels turned otherwise than the sensor by more than this
  // fraction of the sensor's turn, or this many radians (the simulator's
  // slip, one wheel 30 % fast for 0.3 s at 1 m/s, turns the wheels' heading
  // by 0.16 rad; calibrated wheels agree to a few percent).
  double slip_turn_fraction = 0.1;
  double slip_turn_min = 0.02;  // rad
};

struct MountingResult {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // body_from_sensor
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();            // rad, the config's roll, pitch, yaw
  Eigen::Vector2d lever_arm = Eigen::Vector2d::Zero();      // m: the sensor's x, y in the body frame
  Eigen::Vector3d rpy_sd = Eigen::Vector3d::Zero();         // rad, standard deviations
  Eigen::Vector2d lever_arm_sd = Eigen::Vector2d::Zero();   // m
  bool lever_arm_observable = false;  // enough windows turned (min_turn_for_arm) and drove
  bool yaw_observable = false;        // enough windows drove straight enough to show the heading
  std::size_t windows = 0;            // used in step 2
  std::size_t axis_spans = 0;         // long turns step 1 used (0: it used the windows)
  bool from_ground = false;           // roll and pitch from the floor's normal
  double turns_to_ground = 0.0;       // rad: the turns' axis from the floor's normal (with the floor)
  std::size_t outliers = 0;           // dropped: off the plane, a slip, or beyond outlier_sigmas in step 2
  std::size_t turning_windows = 0;    // of them, turning at least min_turn_for_arm
  std::size_t straight_windows = 0;   // of them, driving at least min_travel and turning less
  double rms_axis = 0.0;              // rad: the sensor's rotation across u per window, after the fit
  double rms_planar = 0.0;            // m: the planar equation's residual per window, after the fit
  double rms_planar_before = 0.0;     // m: with the levelled sensor at the body's origin, yaw 0
};

// Throws std::invalid_argument naming what is missing: too few windows with
// both poses and wheel samples, or a drive that never turns (no axis).
// `sensor`: the sensor's poses in the odometry frame, stamped on the LiDAR's
// clock; `ground`: the floor seen from the sensor over the drive, when known.
MountingResult calibrate_mounting(const slam::Trajectory& sensor, std::span<const slam::WheelSample> wheels,
                                  const MountingOptions& options, const std::optional<GroundSummary>& ground = std::nullopt);

}  // namespace adit::eval
