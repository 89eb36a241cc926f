#pragma once
// Synthetic surfaces for registration tests: a closed room and a long, plain
// tunnel (a box corridor), sampled as points in the world frame.

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>

namespace adit::slam::test {

// Points on the six faces of an axis-aligned box [-hx,hx]×[-hy,hy]×[-hz,hz],
// uniformly at random, plus a few boxes (pillars) so that a room is not just
// symmetric planes.
inline std::vector<Eigen::Vector3f> room(std::size_t n, unsigned seed, float hx = 6.0F, float hy = 4.0F,
                                         float hz = 2.0F, bool pillars = true) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0F, 1.0F);
  std::uniform_int_distribution<int> face(0, pillars ? 7 : 5);
  std::vector<Eigen::Vector3f> points;
  points.reserve(n);
  while (points.size() < n) {
    const int f = face(rng);
    const float a = u(rng);
    const float b = u(rng);
    switch (f) {
      case 0: points.emplace_back(hx, a * hy, b * hz); break;
      case 1: points.emplace_back(-hx, a * hy, b * hz); break;
      case 2: points.emplace_back(a * hx, hy, b * hz); break;
      case 3: points.emplace_back(a * hx, -hy, b * hz); break;
      case 4: points.emplace_back(a * hx, b * hy, hz); break;
      case 5: points.emplace_back(a * hx, b * hy, -hz); break;
      case 6: points.emplace_back(2.0F + 0.3F * a, 1.5F, b * hz); break;   // a pillar's face
      default: points.emplace_back(-3.0F, -1.0F + 0.4F * a, b * hz); break;  // another pillar's face
    }
  }
  return points;
}

// A corridor along x of the given length: four plain walls, no ends in view.
inline std::vector<Eigen::Vector3f> tunnel(std::size_t n, unsigned seed, float length = 200.0F) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> along(-length / 2, length / 2);
  std::uniform_real_distribution<float> u(-1.0F, 1.0F);
  std::uniform_int_distribution<int> face(0, 3);
  std::vector<Eigen::Vector3f> points;
  points.reserve(n);
  while (points.size() < n) {
    const float x = along(rng);
    const float a = u(rng);
    switch (face(rng)) {
      case 0: points.emplace_back(x, 2.0F, a * 2.25F); break;
      case 1: points.emplace_back(x, -2.0F, a * 2.25F); break;
      case 2: points.emplace_back(x, a * 2.0F, 2.25F); break;
      default: points.emplace_back(x, a * 2.0F, -2.25F); break;
    }
  }
  return points;
}

// What a 16-beam spinning LiDAR (±15° in 2° steps, 0.2° azimuth steps, as a
// VLP-16) at `pose` sees from inside the box [-hx,hx]×[-hy,hy]×[-hz,hz], in
// its own frame, with Gaussian range noise: rings, not a random sample, so
// planes fitted through map points meet what they meet on real scans.
inline std::vector<Eigen::Vector3f> ring_scan_in_box(const Eigen::Isometry3d& pose, float hx, float hy, float hz,
                                                     float range_sigma_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0F, range_sigma_m);
  const Eigen::Vector3d h(hx, hy, hz);
  std::vector<Eigen::Vector3f> points;
  points.reserve(16 * 1800);
  for (int beam = 0; beam < 16; ++beam) {
    const double elevation = (-15.0 + 2.0 * beam) * M_PI / 180.0;
    for (int step = 0; step < 1800; ++step) {
      const double azimuth = 0.2 * step * M_PI / 180.0;
      const Eigen::Vector3d d(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                              std::sin(elevation));
      const Eigen::Vector3d o = pose.translation();
      const Eigen::Vector3d w = pose.linear() * d;
      double range = 1e9;
      for (int a = 0; a < 3; ++a) {
        if (std::abs(w[a]) < 1e-12) continue;
        range = std::min(range, ((w[a] > 0.0 ? h[a] : -h[a]) - o[a]) / w[a]);
      }
      points.push_back((d * (range + noise(rng))).cast<float>());
    }
  }
  return points;
}

inline std::vector<Eigen::Vector3f> transformed(const std::vector<Eigen::Vector3f>& points,
                                                const Eigen::Isometry3d& T) {
  std::vector<Eigen::Vector3f> out;
  out.reserve(points.size());
  const Eigen::Isometry3f Tf = T.cast<float>();
  for (const auto& p : points) out.push_back(Tf * p);
  return out;
}

}  // namespace adit::slam::test
