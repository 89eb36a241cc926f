// The pose graph's path for clients (graph_path.hpp).
#include "adit/daemon/graph_path.hpp"

#include <algorithm>

namespace adit::daemon {

GraphPath graph_path_of(const slam::CorrectionTrack& track, std::size_t max_points) {
  GraphPath out;
  const std::vector<Eigen::Vector3d>& at = track.graph_positions();
  const std::size_t n = at.size();
  if (n == 0) return out;
  out.utime = track.stamps_ns().back() / 1000;
  out.n_keyframes = static_cast<std::int32_t>(n);
  const std::size_t m = std::min(n, std::max<std::size_t>(max_points, 2));
  out.positions.reserve(m);
  for (std::size_t j = 0; j < m; ++j) {
    // j·(n−1)/(m−1) rounded: 0 and n−1 at the ends, evenly between.
    const std::size_t k = m == 1 ? 0 : (j * (n - 1) + (m - 1) / 2) / (m - 1);
    out.positions.push_back({static_cast<float>(at[k].x()), static_cast<float>(at[k].y()), static_cast<float>(at[k].z())});
  }
  return out;
}

}  // namespace adit::daemon
