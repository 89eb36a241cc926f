#include "adit/slam/wheel_prior.hpp"

#include <cmath>

namespace adit::slam {
namespace {
Eigen::Isometry3d planar(const Pose2& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(p.theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << p.x, p.y, 0.0;
  return T;
}
}  // namespace

MotionPrior wheel_motion_prior(const Pose2& from, const Pose2& to, double distance) {
  MotionPrior prior;
  prior.delta = planar(from).inverse() * planar(to);
  // A per-cent of the distance along the ground plus a floor (slip,
  // quantisation), a per-cent of the turn in yaw.
  const double ds = std::abs(distance);
  const double turn = std::abs(wrap_angle(to.theta - from.theta));
  const double s_xy = 0.01 + 0.02 * ds;
  const double s_yaw = 0.005 + 0.05 * turn + 0.005 * ds;
  Vector6d sigma;
  sigma << s_xy, s_xy, 0.05, 0.02, 0.02, s_yaw;
  prior.covariance = sigma.cwiseAbs2().asDiagonal();
  return prior;
}

}  // namespace adit::slam
