#include "adit/sim/imu_kinematics.hpp"

#include <algorithm>
#include <cmath>

namespace adit::sim {

Eigen::Vector3d body_angular_rate(const BodyTrack& body, double t, double period_s) {
  const Eigen::Matrix3d a = body.pose(t - 0.5 * period_s).linear();
  const Eigen::Matrix3d b = body.pose(t + 0.5 * period_s).linear();
  const Eigen::AngleAxisd turn(a.transpose() * b);
  return turn.axis() * (turn.angle() / period_s);
}

Eigen::Vector3d body_acceleration(const BodyTrack& body, double t, ImuMotion motion) {
  if (motion == ImuMotion::smooth) {
    const double h = kSmoothSpan;
    return (body.pose(t + h).translation() - 2.0 * body.pose(t).translation() + body.pose(t - h).translation()) /
           (h * h);
  }
  // The wheel model at the track's samples, linearly between them.
  const std::size_t n = body.samples().size();
  if (n < 2) return Eigen::Vector3d::Zero();
  const double x = std::clamp(t, 0.0, body.duration()) * BodyTrack::kRate;
  const auto i = std::min(static_cast<std::size_t>(x), n - 2);
  const double f = std::min(x - static_cast<double>(i), 1.0);
  const Eigen::Vector3d a0 = wheeled_acceleration(body, i);
  if (f == 0.0) return a0;
  return a0 + f * (wheeled_acceleration(body, i + 1) - a0);
}

ImuKinematics imu_kinematics(const BodyTrack& body, double t, double period_s, const Eigen::Isometry3d& mount,
                             ImuMotion motion) {
  const Eigen::Matrix3d r = body.pose(t).linear();
  const Eigen::Vector3d omega = body_angular_rate(body, t, period_s);
  const Eigen::Vector3d alpha =
      (body_angular_rate(body, t + 0.5 * period_s, period_s) - body_angular_rate(body, t - 0.5 * period_s, period_s)) /
      period_s;
  const Eigen::Vector3d lever = mount.translation();
  const Eigen::Vector3d force = r.transpose() * (body_acceleration(body, t, motion) + Eigen::Vector3d(0, 0, kStandardGravity)) +
                                alpha.cross(lever) + omega.cross(omega.cross(lever));
  const Eigen::Matrix3d axes = mount.linear();
  return {axes.transpose() * omega, axes.transpose() * force};
}

}  // namespace adit::sim
