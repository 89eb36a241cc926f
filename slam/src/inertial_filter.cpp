#include "adit/slam/inertial_filter.hpp"

#include <algorithm>
#include <cmath>

#include "inertial_kinematics.hpp"

namespace adit::slam {
namespace {

using kinematics::covers;
using kinematics::exp_so3;
using kinematics::for_each_piece;
using kinematics::integrate;
using kinematics::Reading;

using kinematics::kBa;
using kinematics::kBg;
using kinematics::kG;
using kinematics::kP;
using kinematics::kTheta;
using kinematics::kV;

}  // namespace

InertialFilter::InertialFilter(const InertialConfig& config) : config_(config) {}

void InertialFilter::reset(const InertialState& state, const Matrix6d& pose_covariance) {
  state_ = state;
  covariance_.setZero();
  covariance_.topLeftCorner<6, 6>() = pose_covariance;
  const auto set = [&](int block, double sigma) { covariance_.block<3, 3>(block, block).diagonal().setConstant(sigma * sigma); };
  set(kV, config_.initial_velocity_sigma_mps);
  set(kBg, config_.initial_gyro_bias_sigma_radps);
  set(kBa, config_.initial_accel_bias_sigma_mps2);
  set(kG, config_.initial_gravity_sigma_mps2);
}

bool InertialFilter::propagate(std::span<const ImuSample> samples, double t_end) {
  if (!covers(samples, state_.t, t_end, config_.max_sample_gap_s)) return false;
  for_each_piece(samples, state_.t, t_end, [&](const Reading& a, const Reading& b, double dt) {
    const Eigen::Matrix3d R = state_.pose.linear();
    const auto [w, f] = integrate(state_, a, b, dt, config_.imu_position);
    kinematics::propagate_covariance(covariance_, R, w, f, dt, config_);
  });
  state_.t = t_end;  // the pieces' sum, without its rounding
  return true;
}

bool InertialFilter::predict_motion(std::span<const ImuSample> samples, double t_end,
                                    std::vector<TimedPose>& motion) const {
  motion.clear();
  if (!covers(samples, state_.t, t_end, config_.max_sample_gap_s)) return false;
  InertialState s = state_;
  const Eigen::Isometry3d start_inverse = state_.pose.inverse();
  motion.push_back({0.0, Eigen::Isometry3d::Identity()});
  for_each_piece(samples, state_.t, t_end, [&](const Reading& a, const Reading& b, double dt) {
    integrate(s, a, b, dt, config_.imu_position);
    motion.push_back({s.t - state_.t, start_inverse * s.pose});
  });
  return true;
}

PosePrior InertialFilter::pose_prior() const {
  PosePrior prior;
  prior.mean = state_.pose;
  // Registration's ρ is the body-frame translation: ρ = Rᵀ·δp.
  const Matrix6d pose_covariance = kinematics::body_pose_covariance(covariance_, state_.pose.linear());
  prior.information = pose_covariance.ldlt().solve(Matrix6d::Identity());
  if (!prior.information.allFinite()) prior.information.setZero();
  return prior;
}

void InertialFilter::update(const Eigen::Isometry3d& pose, const Matrix6d& body_covariance) {
  // The measured pose's error in this filter's coordinates.
  Vector6d delta;
  delta.head<3>() = pose.translation() - state_.pose.translation();
  const Eigen::AngleAxisd turn(state_.pose.linear().transpose() * pose.linear());
  delta.tail<3>() = turn.angle() * turn.axis();
  Matrix6d M = Matrix6d::Identity();  // δp = R·ρ
  M.topLeftCorner<3, 3>() = pose.linear();
  const Matrix6d posterior = M * body_covariance * M.transpose();

  const Matrix6d prior = covariance_.topLeftCorner<6, 6>();
  const Eigen::Matrix<double, 18, 6> cross = covariance_.leftCols<6>();
  const Eigen::Matrix<double, 18, 6> gain = prior.ldlt().solve(cross.transpose()).transpose();
  if (!gain.allFinite()) return;
  const Eigen::Matrix<double, 18, 1> dx = gain * delta;
  covariance_ -= gain * (prior - posterior) * gain.transpose();
  covariance_ = 0.5 * (covariance_ + covariance_.transpose()).eval();

  state_.pose = pose;
  state_.velocity += dx.segment<3>(kV);
  state_.gyro_bias += dx.segment<3>(kBg);
  state_.accel_bias += dx.segment<3>(kBa);
  state_.gravity += dx.segment<3>(kG);
}

void InertialFilter::update_zero_velocity(double sigma_mps) {
  const Eigen::Matrix3d innovation_covariance =
      covariance_.block<3, 3>(kV, kV) + sigma_mps * sigma_mps * Eigen::Matrix3d::Identity();
  const Eigen::Matrix<double, 18, 3> cross = covariance_.middleCols<3>(kV);
  const Eigen::Matrix<double, 18, 3> gain = innovation_covariance.ldlt().solve(cross.transpose()).transpose();
  if (!gain.allFinite()) return;
  const Eigen::Matrix<double, 18, 1> dx = gain * (-state_.velocity);
  covariance_ -= gain * cross.transpose();
  covariance_ = 0.5 * (covariance_ + covariance_.transpose()).eval();

  state_.pose.translation() += dx.segment<3>(kP);
  state_.pose.linear() = state_.pose.linear() * exp_so3(dx.segment<3>(kTheta));
  state_.velocity += dx.segment<3>(kV);
  state_.gyro_bias += dx.segment<3>(kBg);
  state_.accel_bias += dx.segment<3>(kBa);
  state_.gravity += dx.segment<3>(kG);
}

}  // namespace adit::slam
