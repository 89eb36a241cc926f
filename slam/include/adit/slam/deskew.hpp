#pragma once
// Motion compensation of a scan ("deskewing"): each point was measured at its
// own firing time while the sensor moved; assuming constant body velocity ξ
// over the scan (twist per second, [v; ω], body frame), a point measured at
// time t after the scan start is moved into the body frame at the start by
// T(t) = exp(t·ξ) (Barfoot 2017, §7.1.3; as in KISS-ICP §III-A).
//
// exp() per point is the cost, so T is tabulated at kBins instants across the
// scan and each point takes the nearest one: at 90°/s and 0.1 s per scan the
// angular step is 0.009°, under 2 mm at 10 m. The table lives in the object,
// so deskewing allocates nothing.

#include <array>
#include <span>

#include <Eigen/Geometry>

#include "adit/slam/lie.hpp"

namespace adit::slam {

// The body's pose at time `t` after the scan start, relative to its pose at
// the start (e.g. integrated from an IMU).
struct TimedPose {
  double t = 0.0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

// `Bins` instants: 1024 for a whole scan (odometry, mapping); registration
// redoes its few hundred points every iteration and takes 128 (0.03° steps
// at 40°/s over 0.1 s). Instantiated for 1024 and 128 (deskew.cpp).
template <int Bins>
class TabulatedDeskewer {
 public:
  static constexpr int kBins = Bins;

  // `times_s` holds each point's time after the scan start; `out` receives the
  // deskewed points (same size as `points`; it may alias `points`).
  void deskew(std::span<const Eigen::Vector3f> points, std::span<const float> times_s, const Vector6d& velocity,
              std::span<Eigen::Vector3f> out);
  // The same with the motion given as poses (ascending in t): interpolated
  // between them on SE(3) (T_j·exp(s·log(T_j⁻¹·T_j+1))), held beyond them.
  void deskew(std::span<const Eigen::Vector3f> points, std::span<const float> times_s,
              std::span<const TimedPose> motion, std::span<Eigen::Vector3f> out);

 private:
  // Moves each point by the table entry nearest its time.
  void apply(std::span<const Eigen::Vector3f> points, std::span<const float> times_s, float bin_width,
             std::span<Eigen::Vector3f> out) const;

  std::array<Eigen::Matrix3f, Bins> rotations_;
  std::array<Eigen::Vector3f, Bins> translations_;
};

using Deskewer = TabulatedDeskewer<1024>;

}  // namespace adit::slam
