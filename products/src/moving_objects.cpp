#include "adit/products/moving_objects.hpp"

#include "adit/products/session_scans.hpp"

namespace adit::products {

MovingObjectsReport remove_moving_objects(const std::filesystem::path& session_dir, SessionInputs& inputs,
                                          std::span<const std::uint8_t> keep, const SeeThroughOptions& options) {
  MovingObjectsReport r;
  if (!options.enabled) {
    r.skipped_because = "turned off";
    return r;
  }
  std::vector<Eigen::Vector3f> points;
  points.reserve(inputs.points.size());
  for (const protocol::MapPoint& p : inputs.points)
    points.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z));
  std::vector<std::uint8_t> candidate(points.size(), 1);
  for (std::size_t i = 0; i < keep.size() && i < candidate.size(); ++i) candidate[i] = keep[i] ? 0 : 1;
  for (const std::uint8_t c : candidate) r.candidates += c;
  const auto pass = [&](const std::vector<std::uint8_t>& tested, int scan_step, bool retire, SessionScanStats& stats) {
    SeeThroughCounter counter(points, tested, options, retire);
    stats = for_each_session_scan(session_dir, inputs.body_poses, inputs.body_to_sensor, scan_step,
                                  [&](const RangeImage& image, const ScanPoses& poses) { counter.add_scan(image, poses); });
    return counter;
  };
  SessionScanStats stats;
  if (options.coarse_step > 0) {
    const SeeThroughCounter coarse = pass(candidate, options.coarse_step, true, stats);
    for (std::size_t i = 0; i < candidate.size(); ++i) candidate[i] = coarse.through(i) > 0 ? 1 : 0;
    for (const std::uint8_t c : candidate) r.suspects += c;
  }
  const std::vector<std::uint8_t> dynamic =
      stats.skipped_because.empty() ? pass(candidate, options.scan_step, false, stats).dynamic() : std::vector<std::uint8_t>{};
  r.scans = stats.scans;
  r.scans_used = stats.used;
  if (!stats.skipped_because.empty() || stats.used == 0) {
    r.skipped_because = stats.skipped_because.empty() ? "no scan of the recording lies on the map's trajectory"
                                                       : stats.skipped_because;
    return r;
  }
  r.ran = true;
  std::size_t out = 0;
  for (std::size_t i = 0; i < inputs.points.size(); ++i) {
    if (dynamic[i]) {
      r.removed_points.push_back(inputs.points[i]);
    } else {
      inputs.points[out++] = inputs.points[i];
    }
  }
  inputs.points.resize(out);
  r.removed = r.removed_points.size();
  return r;
}

}  // namespace adit::products
