#pragma once
// The inertial half of LiDAR-inertial odometry: an error-state Kalman filter
// on the body's pose, velocity, IMU biases and gravity, propagated with the
// gyroscope and accelerometer between scans and corrected by each scan's
// registration (the iterated error-state filter of FAST-LIO2, Xu et al.
// 2022, §IV, with the scan's point-to-plane residuals as the measurement).
//
// Propagation: the nominal state by midpoint integration of the samples, the
// error state's covariance by the linearised error dynamics of Solà 2017
// ("Quaternion kinematics for the error-state Kalman filter", §5.3.3, the
// angular error local: R = R̂·exp(δθ)), with the datasheet noise densities
// and bias random walks (an Allan deviation plot's N and K) as its noise.
//
// Update: the registration minimises the scan's residuals plus the
// propagated pose's Gaussian prior (pose_prior()), iterating the
// linearisation as the iterated filter does; its result is a Gaussian on
// the pose alone. The residuals do not depend on velocity, biases or
// gravity, so the posterior of those is the prior conditioned on that
// pose (update()): δx = K·δpose with K = P_x,pose·P_pose⁻¹, and
// P⁺ = P − K·(P_pose − Σ⁺)·Kᵀ. For a measurement that sees only the pose
// this is the Kalman update itself (the gain's pose rows are I), written in
// the form that takes the registration's joint estimate as it comes.
//
// Error state, 18: [δp (world), δθ (body), δv (world), δb_g, δb_a, δg
// (world)]; the pose block is ordered as registration's twists [v; ω]
// (δp = R̂·ρ for registration's body-frame translation ρ).

#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "adit/slam/deskew.hpp"
#include "adit/slam/imu_sample.hpp"
#include "adit/slam/lie.hpp"
#include "adit/slam/registration.hpp"

namespace adit::slam {

using Matrix18d = Eigen::Matrix<double, 18, 18>;

// Continuous-time noise of the IMU, as a datasheet or an Allan deviation
// plot gives it. Vibration that the datasheet does not know of (rotors,
// engines) belongs in the densities too.
struct ImuNoise {
  double gyro_noise_density = 1.7e-4;  // rad/s/√Hz (angle random walk)
  double accel_noise_density = 2.0e-3; // m/s²/√Hz (velocity random walk)
  double gyro_bias_walk = 1.9e-5;      // rad/s²/√Hz
  double accel_bias_walk = 3.0e-3;     // m/s³/√Hz
};

struct InertialConfig {
  ImuNoise noise;
  // What the datasheet's white noise leaves out and the filter must allow
  // for (vibration, timing, scale factor, axis misalignment, integration
  // error), added to `noise`'s densities in quadrature. FAST-LIO2 runs real
  // payloads with 0.1 per sample (rad²/s², m²/s⁴) at the IMU rate, about
  // 0.02/√Hz at 200 Hz; drives track alike from 0.006 to 0.06
  // (docs/decisions/020-lio-noise-and-scan-weight.md).
  double gyro_model_error_density = 0.02;   // rad/s/√Hz
  double accel_model_error_density = 0.02;  // m/s²/√Hz
  // The IMU's origin in the body frame: the accelerometer there also feels
  // the rotation's centripetal and tangential accelerations, removed before
  // integration (f_body = f − ω×(ω×r) − α×r).
  Eigen::Vector3d imu_position = Eigen::Vector3d::Zero();
  // What is known at the start. The velocity may already be non-zero (a
  // drone started in flight); turn-on biases of a MEMS unit are about
  // 0.5°/s and 50 mg; gravity's direction is taken from the specific force
  // then, which a moving start's acceleration tilts.
  double initial_velocity_sigma_mps = 2.0;
  double initial_gyro_bias_sigma_radps = 0.01;
  double initial_accel_bias_sigma_mps2 = 0.5;
  double initial_gravity_sigma_mps2 = 0.3;
  // Samples further apart than this: the IMU dropped out, no propagation.
  double max_sample_gap_s = 0.05;
};

struct InertialState {
  double t = 0.0;  // s, on the LiDAR clock
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();    // world
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();   // rad/s
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();  // m/s²
  Eigen::Vector3d gravity = Eigen::Vector3d(0.0, 0.0, -9.80665);  // world, m/s²
};

class InertialFilter {
 public:
  explicit InertialFilter(const InertialConfig& config);

  // Starts (or starts again) at `state`, with the configured initial
  // uncertainty on velocity, biases and gravity and `pose_covariance` on the
  // pose (error-state order [δp; δθ]).
  void reset(const InertialState& state, const Matrix6d& pose_covariance = Matrix6d::Zero());

  // Propagates state and covariance to `t_end` with `samples` (gyroscope
  // ones, ascending in t, covering [state().t, t_end] within
  // max_sample_gap_s at either end and between samples). False, and nothing
  // changed, when they do not.
  bool propagate(std::span<const ImuSample> samples, double t_end);

  // The body's motion from the state's time to `t_end` (relative to the
  // state's pose), from the nominal state alone, into `motion` (cleared;
  // capacity kept), one pose per sample and one at t_end: the deskewing of
  // a sweep. False when the samples do not cover the interval.
  bool predict_motion(std::span<const ImuSample> samples, double t_end, std::vector<TimedPose>& motion) const;

  // The propagated pose as a registration prior: mean and information in
  // registration's body tangent space.
  PosePrior pose_prior() const;

  // Conditions the state on a registered pose with its covariance in the
  // body tangent at that pose ([v; ω], pose·exp(ε)).
  void update(const Eigen::Isometry3d& pose, const Matrix6d& body_covariance);

  // Conditions the state on the body being still: velocity zero with σ
  // `sigma_mps` per axis (a zero-velocity update, standstill.hpp). The
  // Kalman update of the measurement v = 0 (H selects δv); through the
  // covariance it also moves the pose, the biases and gravity.
  void update_zero_velocity(double sigma_mps);

  const InertialState& state() const { return state_; }
  const Matrix18d& covariance() const { return covariance_; }
  const InertialConfig& config() const { return config_; }

 private:
  InertialConfig config_;
  InertialState state_;
  Matrix18d covariance_ = Matrix18d::Zero();
};

}  // namespace adit::slam
