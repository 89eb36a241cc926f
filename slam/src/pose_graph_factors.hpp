#pragma once
// The pose graph's factors as Ceres auto-differentiated cost functors
// (private to slam/: only pose_graph_solver.cpp sees Ceres). A pose is a unit
// quaternion q (Eigen's x, y, z, w order, on ceres::EigenQuaternionManifold)
// and a translation p.

#include <cmath>

#include <ceres/ceres.h>
#include <Eigen/Geometry>

#include "adit/slam/lie.hpp"

namespace adit::slam::detail {

// A measured pose z = (p_z, q_z) and the residual of an estimate (p̂, q̂) of it
// (the SE(3) pose-graph residual of Carlone et al., ICRA 2015, §II, in the
// quaternion form of Ceres's pose_graph_3d example):
//   e = [p̂ − p_z ; 2·vec(q_z⁻¹·q̂)]        (2·vec ≈ the rotation vector for small errors)
// whitened by the square root of the information, L with LᵀL = Λ.
struct PoseResidual {
  PoseResidual(const Eigen::Isometry3d& z, const Matrix6d& sqrt_information)
      : p_z(z.translation()), q_z(z.linear()), L(sqrt_information) {}

  template <typename T>
  void operator()(const Eigen::Matrix<T, 3, 1>& p_hat, const Eigen::Quaternion<T>& q_hat, T* r_) const {
    const Eigen::Quaternion<T> q_err = q_z.template cast<T>().conjugate() * q_hat;
    Eigen::Matrix<T, 6, 1> e;
    e << p_hat - p_z.template cast<T>(), T(2.0) * q_err.vec();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(r_);
    r = L.template cast<T>() * e;
  }

  Eigen::Vector3d p_z;
  Eigen::Quaterniond q_z;
  Matrix6d L;
};

// Relative pose: p̂ = R_a⁻¹(p_b − p_a), q̂ = q_a⁻¹·q_b.
struct RelativePoseFactor {
  RelativePoseFactor(const Eigen::Isometry3d& z, const Matrix6d& sqrt_information) : residual(z, sqrt_information) {}

  template <typename T>
  bool operator()(const T* qa_, const T* pa_, const T* qb_, const T* pb_, T* r_) const {
    const Eigen::Map<const Eigen::Quaternion<T>> qa(qa_), qb(qb_);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> pa(pa_), pb(pb_);
    const Eigen::Quaternion<T> qa_inv = qa.conjugate();
    residual(Eigen::Matrix<T, 3, 1>(qa_inv * (pb - pa)), Eigen::Quaternion<T>(qa_inv * qb), r_);
    return true;
  }

  static ceres::CostFunction* create(const Eigen::Isometry3d& z, const Matrix6d& sqrt_information) {
    // Ceres takes ownership of the functor and the cost function (its API).
    return new ceres::AutoDiffCostFunction<RelativePoseFactor, 6, 4, 3, 4, 3>(
        new RelativePoseFactor(z, sqrt_information));
  }

  PoseResidual residual;
};

// Absolute pose: p̂ = p, q̂ = q (a node held where a prior map placed it).
struct AbsolutePoseFactor {
  AbsolutePoseFactor(const Eigen::Isometry3d& z, const Matrix6d& sqrt_information) : residual(z, sqrt_information) {}

  template <typename T>
  bool operator()(const T* q_, const T* p_, T* r_) const {
    residual(Eigen::Matrix<T, 3, 1>(Eigen::Map<const Eigen::Matrix<T, 3, 1>>(p_)),
             Eigen::Quaternion<T>(Eigen::Map<const Eigen::Quaternion<T>>(q_)), r_);
    return true;
  }

  static ceres::CostFunction* create(const Eigen::Isometry3d& z, const Matrix6d& sqrt_information) {
    return new ceres::AutoDiffCostFunction<AbsolutePoseFactor, 6, 4, 3>(new AbsolutePoseFactor(z, sqrt_information));
  }

  PoseResidual residual;
};

// Gravity: R·u_b − e_z, as the registration's gravity term
// (slam/registration.hpp, GravityPrior); yaw is free.
struct GravityFactor {
  GravityFactor(const Eigen::Vector3d& up_body, double sqrt_information) : u_b(up_body), s(sqrt_information) {}

  template <typename T>
  bool operator()(const T* q_, T* r_) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(r_);
    r = T(s) * (q * u_b.template cast<T>() - Eigen::Matrix<T, 3, 1>::UnitZ());
    return true;
  }

  static ceres::CostFunction* create(const Eigen::Vector3d& up_body, double information) {
    return new ceres::AutoDiffCostFunction<GravityFactor, 3, 4>(new GravityFactor(up_body, std::sqrt(information)));
  }

  Eigen::Vector3d u_b;
  double s;
};

// Gravity with a tilt offset δ (rad about the body's x and y axes) on the
// measured up: R·normalise(u_b + [δx, δy, 0] × u_b) − e_z.
struct TiltedGravityFactor {
  TiltedGravityFactor(const Eigen::Vector3d& up_body, double sqrt_information) : u_b(up_body), s(sqrt_information) {}

  template <typename T>
  bool operator()(const T* q_, const T* delta_, T* r_) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_);
    const Eigen::Matrix<T, 3, 1> d(delta_[0], delta_[1], T(0.0));
    const Eigen::Matrix<T, 3, 1> u = u_b.template cast<T>();
    const Eigen::Matrix<T, 3, 1> turned = (u + d.cross(u)).normalized();
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(r_);
    r = T(s) * (q * turned - Eigen::Matrix<T, 3, 1>::UnitZ());
    return true;
  }

  static ceres::CostFunction* create(const Eigen::Vector3d& up_body, double information) {
    return new ceres::AutoDiffCostFunction<TiltedGravityFactor, 3, 4, 2>(
        new TiltedGravityFactor(up_body, std::sqrt(information)));
  }

  Eigen::Vector3d u_b;
  double s;
};

// The tilt offset's random walk between two gravity priors: (δ_b − δ_a)/σ.
struct TiltWalkFactor {
  explicit TiltWalkFactor(double sigma) : inverse_sigma(1.0 / sigma) {}

  template <typename T>
  bool operator()(const T* a, const T* b, T* r) const {
    r[0] = T(inverse_sigma) * (b[0] - a[0]);
    r[1] = T(inverse_sigma) * (b[1] - a[1]);
    return true;
  }

  static ceres::CostFunction* create(double sigma) {
    return new ceres::AutoDiffCostFunction<TiltWalkFactor, 2, 2, 2>(new TiltWalkFactor(sigma));
  }

  double inverse_sigma;
};

}  // namespace adit::slam::detail
