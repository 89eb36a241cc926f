// Loop candidates by the graph's uncertainty and Scan Context (place_recognition.hpp).
#include "adit/slam/place_recognition.hpp"

#include <algorithm>
#include <cmath>

namespace adit::slam {

std::vector<LoopCandidate> find_loop_candidates(std::size_t query, const ScanContext& query_descriptor,
                                                const KeyframeIndexView& k, const DescriptorReader& read_descriptor,
                                                const PlaceRecognitionConfig& config) {
  std::vector<LoopCandidate> out;
  if (query >= k.ring_keys.size() || query >= k.poses.size() || query >= k.path_m.size() ||
      query >= k.position_variance.size())
    return out;
  const Eigen::Vector3d here = k.poses[query].translation();
  struct Gated {
    std::size_t index;
    float ring_distance;
    double gap;
  };
  std::vector<Gated> gated;
  for (std::size_t j = 0; j < query; ++j) {
    if (k.path_m[query] - k.path_m[j] < config.min_path_separation_m) break;  // path_m grows: the rest are nearer
    const double variance = std::max(0.0, k.position_variance[query] - k.position_variance[j]);
    const double radius = config.base_radius_m + config.gate_sigmas * std::sqrt(variance);
    const double gap = (k.poses[j].translation() - here).norm();
    if (gap > radius) continue;
    gated.push_back({j, ring_key_distance(query_descriptor.ring_key, k.ring_keys[j]), gap});
  }
  const std::size_t keep = std::min(gated.size(), static_cast<std::size_t>(std::max(0, config.ring_key_candidates)));
  std::partial_sort(gated.begin(), gated.begin() + static_cast<std::ptrdiff_t>(keep), gated.end(),
                    [](const Gated& a, const Gated& b) { return a.ring_distance < b.ring_distance; });
  ScanContext old;  // compare() reads the bins only
  for (std::size_t i = 0; i < keep; ++i) {
    if (!read_descriptor(gated[i].index, old.bins)) continue;
    const ScanContextMatch m = compare(query_descriptor, old);
    if (m.distance > config.max_descriptor_distance) continue;
    out.push_back({query, gated[i].index, m.distance, m.yaw_rad, m.alternative_yaw_rad, m.alternative_distance,
                   gated[i].gap});
  }
  std::sort(out.begin(), out.end(),
            [](const LoopCandidate& a, const LoopCandidate& b) { return a.descriptor_distance < b.descriptor_distance; });
  if (out.size() > static_cast<std::size_t>(std::max(0, config.max_candidates)))
    out.resize(static_cast<std::size_t>(config.max_candidates));
  return out;
}

}  // namespace adit::slam
