// Scan Context descriptor and its shift-searched distance (scan_context.hpp).
#include "adit/slam/scan_context.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace adit::slam {

ScanContext make_scan_context(std::span<const Eigen::Vector3f> points, const ScanContextConfig& config) {
  ScanContext sc;
  sc.bins = Eigen::MatrixXf::Zero(config.rings, config.sectors);
  sc.ring_key = Eigen::VectorXf::Zero(config.rings);
  float lowest = std::numeric_limits<float>::infinity();
  const float max2 = config.max_radius_m * config.max_radius_m;
  for (const Eigen::Vector3f& p : points) {
    if (p.head<2>().squaredNorm() < max2 && std::isfinite(p.z())) lowest = std::min(lowest, p.z());
  }
  if (!std::isfinite(lowest)) return sc;
  const float ring_width = config.max_radius_m / static_cast<float>(config.rings);
  const float sector_width = 2.0F * std::numbers::pi_v<float> / static_cast<float>(config.sectors);
  for (const Eigen::Vector3f& p : points) {
    const float r2 = p.head<2>().squaredNorm();
    if (!(r2 < max2) || !std::isfinite(p.z())) continue;
    const int ring = std::min(config.rings - 1, static_cast<int>(std::sqrt(r2) / ring_width));
    // Azimuth in [0, 2π): sector 0 starts at the body's +x.
    float azimuth = std::atan2(p.y(), p.x());
    if (azimuth < 0.0F) azimuth += 2.0F * std::numbers::pi_v<float>;
    const int sector = std::min(config.sectors - 1, static_cast<int>(azimuth / sector_width));
    float& bin = sc.bins(ring, sector);
    bin = std::max(bin, p.z() - lowest + 1.0F);
  }
  for (int r = 0; r < config.rings; ++r) {
    sc.ring_key[r] = static_cast<float>((sc.bins.row(r).array() > 0.0F).count()) / static_cast<float>(config.sectors);
  }
  return sc;
}

namespace {

// Eq. 5 at one shift: the query's column j against the candidate's column
// (j + shift) mod N_s.
double distance_at(const ScanContext& q, const ScanContext& c, int shift, const Eigen::VectorXf& qn,
                   const Eigen::VectorXf& cn) {
  const int sectors = static_cast<int>(q.bins.cols());
  double sum = 0.0;
  int used = 0;
  for (int j = 0; j < sectors; ++j) {
    const int k = (j + shift) % sectors;
    if (qn[j] == 0.0F && cn[k] == 0.0F) continue;  // empty in both: says nothing
    ++used;
    if (qn[j] == 0.0F || cn[k] == 0.0F) {
      sum += 1.0;
      continue;
    }
    sum += 1.0 - static_cast<double>(q.bins.col(j).dot(c.bins.col(k))) / (static_cast<double>(qn[j]) * cn[k]);
  }
  return used == 0 ? 1.0 : sum / used;
}

}  // namespace

ScanContextMatch compare(const ScanContext& query, const ScanContext& candidate) {
  ScanContextMatch match;
  const int sectors = static_cast<int>(query.bins.cols());
  if (sectors == 0 || candidate.bins.cols() != sectors || candidate.bins.rows() != query.bins.rows()) return match;
  const Eigen::VectorXf qn = query.bins.colwise().norm().transpose();
  const Eigen::VectorXf cn = candidate.bins.colwise().norm().transpose();
  std::vector<double> d(static_cast<std::size_t>(sectors));
  for (int s = 0; s < sectors; ++s) d[static_cast<std::size_t>(s)] = distance_at(query, candidate, s, qn, cn);
  const auto best = static_cast<int>(std::min_element(d.begin(), d.end()) - d.begin());
  const double sector_rad = 2.0 * std::numbers::pi / sectors;
  // The query's sector j sees what the candidate's sector j + s sees: the
  // query's body is turned by +s sectors relative to the candidate's.
  auto yaw_of = [&](int s) { return std::remainder(s * sector_rad, 2.0 * std::numbers::pi); };
  match.distance = d[static_cast<std::size_t>(best)];
  match.yaw_rad = yaw_of(best);
  for (int s = 0; s < sectors; ++s) {
    const double apart = std::abs(std::remainder((s - best) * sector_rad, 2.0 * std::numbers::pi));
    if (apart + 1e-9 < kAlternativeSeparationRad) continue;
    if (d[static_cast<std::size_t>(s)] < match.alternative_distance) {
      match.alternative_distance = d[static_cast<std::size_t>(s)];
      match.alternative_yaw_rad = yaw_of(s);
    }
  }
  return match;
}

}  // namespace adit::slam
