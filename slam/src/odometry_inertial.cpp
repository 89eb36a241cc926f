// Odometry's LiDAR-inertial step (see inertial_filter.hpp for the filter and
// odometry.cpp for the LiDAR-only step it replaces when an IMU is given).

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "adit/slam/gravity.hpp"
#include "adit/slam/odometry.hpp"
#include "start_search.hpp"

namespace adit::slam {
namespace {

double seconds(std::int64_t ns) { return 1e-9 * static_cast<double>(ns); }

bool all_have_gyro(std::span<const ImuSample> samples) {
  return std::all_of(samples.begin(), samples.end(), [](const ImuSample& s) { return s.has_gyro; });
}

// Gaussian priors on one pose multiplied: information added, the mean moved
// towards `other` by its share, in the body tangent at `prior.mean`.
void fuse(PosePrior& prior, const Eigen::Isometry3d& other_mean, const Matrix6d& other_information) {
  const Vector6d e = log_se3(prior.mean.inverse() * other_mean);
  const Matrix6d information = prior.information + other_information;
  const Vector6d shift = information.ldlt().solve(other_information * e);
  if (!shift.allFinite()) return;
  prior.mean = prior.mean * exp_se3(shift);
  prior.information = information;
}

}  // namespace

void Odometry::start_inertial(const ScanInput& scan, const Matrix6d& body_covariance) {
  if (scan.imu.empty() || !all_have_gyro(scan.imu)) return;
  // Gravity's direction from the mean specific force around the scan: at
  // rest f = −Rᵀ·g. Moving, the body's acceleration tilts it by a/g; the
  // filter's gravity state then corrects it (initial_gravity_sigma_mps2).
  constexpr double kWindow = 0.1;
  const double t = seconds(scan.stamp_ns);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (const ImuSample& s : scan.imu)
    if (std::abs(s.t - t) <= kWindow) {
      sum += s.specific_force;
      ++count;
    }
  if (count < 3 || sum.norm() == 0.0) return;
  InertialState state;
  if (inertial_started_) state = inertial_.state();  // biases and gravity as learnt
  else state.gravity = -kStandardGravity * (pose_.linear() * sum).normalized();
  state.t = t;
  state.pose = pose_;
  state.velocity = pose_.linear() * velocity_.head<3>();
  Matrix6d M = Matrix6d::Identity();  // registration's ρ to the filter's δp = R·ρ
  M.topLeftCorner<3, 3>() = pose_.linear();
  inertial_.reset(state, M * body_covariance * M.transpose());
  updated_velocity_ = state.velocity;
  inertial_started_ = true;
}

bool Odometry::predict_inertial(const ScanInput& scan, double sweep_s) {
  const double t = seconds(scan.stamp_ns);
  return all_have_gyro(scan.imu) && inertial_.propagate(scan.imu, t) &&
         inertial_.predict_motion(scan.imu, t + sweep_s, sweep_motion_);
}

void Odometry::register_inertial(const ScanInput& scan, const std::optional<MotionPrior>& wheel,
                                 OdometryResult& result) {
  const double dt = seconds(scan.stamp_ns - last_stamp_ns_);
  const Eigen::Isometry3d predicted = inertial_.state().pose;
  PosePrior prior = inertial_.pose_prior();
  // The wheels, when they agree with the IMU's motion: a spinning or lifted
  // wheel departs from it as it departs from constant velocity (odometry.cpp).
  if (wheel && dt > 0.0) {
    const Vector6d imu_velocity = log_se3(pose_.inverse() * predicted) / dt;
    const Matrix6d wheel_information = wheel->covariance.inverse();
    if (wheel_motion_implausible(wheel->delta, imu_velocity, dt, config_) || !wheel_information.allFinite())
      result.wheel_rejected = true;
    else
      fuse(prior, pose_ * wheel->delta, wheel_information);
  }

  const std::span<Eigen::Vector3f> source = std::span(source_deskewed_).first(source_.size());
  deskewer_.deskew(source_, source_times_, sweep_motion_, source);
  // How far the prediction may be off: the adaptive threshold's σ (KISS-ICP)
  // or the filter's own position σ, whichever is larger (a scan after a long
  // gap, or the velocity not known yet), at most what a reacquisition takes.
  const double reacquire_sigma = config_.initial_threshold_m / 3.0;
  const Eigen::Matrix3d position_covariance = inertial_.covariance().topLeftCorner<3, 3>();
  const double predicted_sigma = std::sqrt(std::max(0.0, position_covariance.selfadjointView<Eigen::Upper>().eigenvalues().maxCoeff()));
  // At least what lets the kernel start at its floor (the range noise's scale):
  // an IMU predicts so well that the prediction's σ alone would gate out the
  // residuals of a correct alignment (range noise, map spacing, plane fit).
  const double floor_sigma = 3.0 * inertial_registration_.min_kernel_scale_m;
  const double sigma = reacquire_ ? reacquire_sigma
                                  : std::clamp(std::max(threshold_.sigma(), predicted_sigma), floor_sigma, reacquire_sigma);
  reacquire_ = false;
  const auto register_from = [&](const PosePrior& start) {
    return register_scan(source, map_, start, 3.0 * sigma, sigma / 3.0, inertial_registration_, planes_, SweepMotion{},
                         prior_term(inertial_registration_.point_sigma_m));
  };
  result.registration = register_from(prior);
  // Moving already when the filter started, at a speed it does not know:
  // the start search of the LiDAR-only step, for the translation (the
  // gyroscope has the rotation).
  if (!wheel && !velocity_known_ && dt > 0.0)
    result.search_cut |= !search_start(config_.max_start_speed_mps * dt, config_.start_search_step_m,
                 config_.wheel_rejection_margin, config_.start_search_noise_sigmas, [this] { return keeping_up(); },
                 [&](const Eigen::Vector2d& offset) {
                   PosePrior start = prior;
                   start.mean = prior.mean * Eigen::Translation3d(offset.x(), offset.y(), 0.0);
                   return register_from(start);
                 },
                 result.registration);
  const Eigen::Isometry3d registered = result.registration.pose;
  threshold_.update(predicted.inverse() * registered, pose_.inverse() * registered);

  const Eigen::Vector3d predicted_velocity = inertial_.state().velocity;
  const Matrix6d to_body = adjoint(registered.inverse());
  inertial_.update(registered, to_body * result.registration.covariance * to_body.transpose());
  // Still wherever the scan can see, no acceleration felt, and slow in the
  // filter's belief: still along the directions the scan cannot see too
  // (standstill.hpp).
  result.standstill = appears_still(pose_, result.registration, dt, predicted_velocity,
                                    predicted_velocity - updated_velocity_, config_.standstill);
  if (result.standstill) inertial_.update_zero_velocity(config_.standstill.velocity_sigma_mps);
  const Eigen::Isometry3d corrected = inertial_.state().pose;
  updated_velocity_ = inertial_.state().velocity;
  // The sweep again with the corrected velocity and biases, for the map.
  const double t = seconds(scan.stamp_ns);
  const double sweep_s = sweep_motion_.empty() ? 0.0 : sweep_motion_.back().t;
  inertial_.predict_motion(scan.imu, t + sweep_s, sweep_motion_);

  // The LiDAR-only state follows, should the IMU drop out.
  if (sweep_s > 0.0) velocity_ = log_se3(sweep_motion_.back().pose) / sweep_s;
  else velocity_ << corrected.linear().transpose() * inertial_.state().velocity, Eigen::Vector3d::Zero();
  velocity_known_ = true;
  start_to_mid_.setIdentity();
  mid_offset_s_ = 0.0;
  last_correspondences_ = static_cast<double>(result.registration.correspondences);
  pose_ = corrected;
  last_stamp_ns_ = scan.stamp_ns;

  deskewed_.resize(frame_.size());
  deskewer_.deskew(frame_, frame_times_, sweep_motion_, deskewed_);
  add_deskewed_to_map();

  result.pose = pose_;
  result.covariance = result.registration.covariance;
  result.sweep_velocity = velocity_;
  result.valid = true;
  result.inertial = true;
  result.status = result.registration.degenerate ? OdometryStatus::degenerate : OdometryStatus::ok;
}

}  // namespace adit::slam
