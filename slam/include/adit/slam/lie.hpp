#pragma once
// SE(3) exponential and logarithm for small pose updates, with the twist
// ordered [translation v; rotation ω]. Formulas: Barfoot, "State Estimation
// for Robotics" (2017), §7.1.3 (eq. 7.83–7.86), Rodrigues for SO(3).

#include <cmath>

#include <Eigen/Geometry>

namespace adit::slam {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

inline Eigen::Matrix3d skew(const Eigen::Vector3d& w) {
  Eigen::Matrix3d s;
  s << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  return s;
}

// exp: se(3) -> SE(3).
inline Eigen::Isometry3d exp_se3(const Vector6d& xi) {
  const Eigen::Vector3d v = xi.head<3>();
  const Eigen::Vector3d w = xi.tail<3>();
  const double theta = w.norm();
  const Eigen::Matrix3d W = skew(w);
  Eigen::Matrix3d R;
  Eigen::Matrix3d V;  // the left Jacobian of SO(3)
  if (theta < 1e-9) {
    R = Eigen::Matrix3d::Identity() + W;
    V = Eigen::Matrix3d::Identity() + 0.5 * W;
  } else {
    const double a = std::sin(theta) / theta;
    const double b = (1.0 - std::cos(theta)) / (theta * theta);
    const double c = (theta - std::sin(theta)) / (theta * theta * theta);
    R = Eigen::Matrix3d::Identity() + a * W + b * W * W;
    V = Eigen::Matrix3d::Identity() + b * W + c * W * W;
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = V * v;
  return T;
}

// log: SE(3) -> se(3), the inverse of exp_se3 for rotations below π.
inline Vector6d log_se3(const Eigen::Isometry3d& T) {
  const Eigen::AngleAxisd aa(T.linear());
  const double theta = aa.angle();
  const Eigen::Vector3d w = aa.axis() * theta;
  const Eigen::Matrix3d W = skew(w);
  Eigen::Matrix3d V_inv;
  if (theta < 1e-9) {
    V_inv = Eigen::Matrix3d::Identity() - 0.5 * W;
  } else {
    const double half = 0.5 * theta;
    const double k = (1.0 - half * std::cos(half) / std::sin(half)) / (theta * theta);
    V_inv = Eigen::Matrix3d::Identity() - 0.5 * W + k * W * W;
  }
  Vector6d xi;
  xi.head<3>() = V_inv * T.translation();
  xi.tail<3>() = w;
  return xi;
}

// The adjoint of SE(3) for twists ordered [v; ω] (Barfoot 2017, eq. 7.32):
// T·exp(ε) = exp(Ad(T)·ε)·T, so a covariance moves between frames as Ad Σ Adᵀ.
inline Matrix6d adjoint(const Eigen::Isometry3d& T) {
  Matrix6d Ad = Matrix6d::Zero();
  const Eigen::Matrix3d R = T.linear();
  Ad.topLeftCorner<3, 3>() = R;
  Ad.topRightCorner<3, 3>() = skew(T.translation()) * R;
  Ad.bottomRightCorner<3, 3>() = R;
  return Ad;
}

}  // namespace adit::slam
