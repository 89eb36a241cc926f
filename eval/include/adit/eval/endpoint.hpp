#pragma once
// End-to-end drift of a platform that returns near its start: the start-to-end
// position difference from the trajectory against the one a total station
// measured on a target fixed to the payload (both in the same frame).

#include <span>

#include <Eigen/Core>

#include "adit/slam/trajectory.hpp"

namespace adit::eval {

struct EndpointDrift {
  Eigen::Vector3d true_delta = Eigen::Vector3d::Zero();       // measured end - start
  Eigen::Vector3d estimated_delta = Eigen::Vector3d::Zero();  // p_last - p_first
  Eigen::Vector3d error = Eigen::Vector3d::Zero();            // true - estimated

  double drift = 0.0;   // |true - estimated|, metres
  double length = 0.0;  // path length L, metres
  double rate = 0.0;    // drift / L (0 when L = 0)
};

EndpointDrift endpoint_drift(std::span<const slam::Pose> poses, const Eigen::Vector3d& true_delta);

}  // namespace adit::eval
