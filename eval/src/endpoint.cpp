#include "adit/eval/endpoint.hpp"

#include "adit/eval/path.hpp"

namespace adit::eval {

EndpointDrift endpoint_drift(std::span<const slam::Pose> poses, const Eigen::Vector3d& true_delta) {
  EndpointDrift out;
  out.true_delta = true_delta;
  if (poses.empty()) return out;
  out.estimated_delta = poses.back().translation() - poses.front().translation();
  out.error = true_delta - out.estimated_delta;
  out.drift = out.error.norm();
  out.length = path_length(poses);
  out.rate = out.length > 0.0 ? out.drift / out.length : 0.0;
  return out;
}

}  // namespace adit::eval
