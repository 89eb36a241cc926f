#pragma once
// Along a trajectory: the distance travelled, and pairs of its poses.

#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include "adit/slam/trajectory.hpp"

namespace adit::eval {

// Indices of two poses: (i, j) in one trajectory, or matched across two.
using IndexPair = std::pair<std::size_t, std::size_t>;

// Cumulative path length: out[0] = 0, out[i] = sum_{k<i} |p_{k+1} - p_k|.
std::vector<double> path_distances(std::span<const slam::Pose> poses);

// Total length of the path through the positions.
double path_length(std::span<const slam::Pose> poses);

}  // namespace adit::eval
