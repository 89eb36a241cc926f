#include "adit/eval/path.hpp"

namespace adit::eval {

std::vector<double> path_distances(std::span<const slam::Pose> poses) {
  std::vector<double> out(poses.size(), 0.0);
  for (std::size_t i = 1; i < poses.size(); ++i)
    out[i] = out[i - 1] + (poses[i].translation() - poses[i - 1].translation()).norm();
  return out;
}

double path_length(std::span<const slam::Pose> poses) {
  double length = 0.0;
  for (std::size_t i = 1; i < poses.size(); ++i) length += (poses[i].translation() - poses[i - 1].translation()).norm();
  return length;
}

}  // namespace adit::eval
