#pragma once
// Synthetic places for loop-closure tests: a square ring of corridors with
// pillars (a level's loop), straight plain corridors (symmetric, featureless
// along the axis), and scans of them from a pose.

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>

namespace adit::slam::test {

// A pose on the floor plane: at (x, y), turned by `yaw` about z.
inline Eigen::Isometry3d pose_at(double x, double y, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << x, y, 0.0;
  return T;
}

// A square ring of corridors, centreline from (0,0) to (L,0) to (L,L) to
// (0,L), 4 m wide (|n| ≤ 2), floor at z = -1.5, ceiling at 2.0; `pillars`
// cylinders of radius 0.3 m at 1.4 m beside the centreline at random places
// so that no two stretches look alike. ~`density` points per m².
inline std::vector<Eigen::Vector3f> ring_corridor(float L, int pillars, unsigned seed, float density = 30.0F) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0F, 1.0F);
  std::vector<Eigen::Vector3f> pts;
  const Eigen::Vector2f origin[4] = {{0, 0}, {L, 0}, {L, L}, {0, L}};
  const Eigen::Vector2f tangent[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
  auto world = [&](int seg, float s, float n, float z) {
    const Eigen::Vector2f t = tangent[seg];
    const Eigen::Vector2f normal(-t.y(), t.x());  // points into the square
    const Eigen::Vector2f xy = origin[seg] + s * t + n * normal;
    return Eigen::Vector3f(xy.x(), xy.y(), z);
  };
  auto sample = [&](float area, auto&& at) {
    const int n = static_cast<int>(area * density);
    for (int i = 0; i < n; ++i) pts.push_back(at(u(rng), u(rng)));
  };
  for (int seg = 0; seg < 4; ++seg) {
    // inner wall spans [2, L-2], outer wall [-2, L+2]; floor and ceiling [-2, L+2]
    sample((L - 4) * 3.5F, [&](float a, float b) { return world(seg, 2 + a * (L - 4), 2.0F, -1.5F + 3.5F * b); });
    sample((L + 4) * 3.5F, [&](float a, float b) { return world(seg, -2 + a * (L + 4), -2.0F, -1.5F + 3.5F * b); });
    sample((L + 4) * 4.0F, [&](float a, float b) { return world(seg, -2 + a * (L + 4), -2 + 4 * b, -1.5F); });
    sample((L + 4) * 4.0F, [&](float a, float b) { return world(seg, -2 + a * (L + 4), -2 + 4 * b, 2.0F); });
  }
  for (int p = 0; p < pillars; ++p) {
    const int seg = static_cast<int>(u(rng) * 4) % 4;
    const float s = 2.0F + u(rng) * (L - 4);
    const Eigen::Vector3f c = world(seg, s, u(rng) < 0.5F ? 1.4F : -1.4F, 0.0F);
    sample(2 * 3.1416F * 0.3F * 3.5F, [&](float a, float b) {
      const float phi = 2 * 3.1416F * a;
      return Eigen::Vector3f(c.x() + 0.3F * std::cos(phi), c.y() + 0.3F * std::sin(phi), -1.5F + 3.5F * b);
    });
  }
  return pts;
}

// The ring's centreline pose at path length s (mod 4L), heading along it.
inline Eigen::Isometry3d ring_pose(float L, double s) {
  s = std::fmod(s, 4.0 * L);
  const int seg = static_cast<int>(s / L);
  const double along = s - seg * L;
  const double yaw = seg * M_PI / 2;
  const Eigen::Vector2d origin[4] = {{0, 0}, {L, 0}, {L, L}, {0, L}};
  const Eigen::Vector2d t(std::cos(yaw), std::sin(yaw));
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << (origin[seg] + along * t), 0.0;
  return T;
}

// A scan of `world` from `pose`: points within `range`, a random half of
// them, 1 cm of noise, in the body frame.
inline std::vector<Eigen::Vector3f> scan_of(const std::vector<Eigen::Vector3f>& world, const Eigen::Isometry3d& pose,
                                            unsigned seed, float range = 25.0F) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0F, 0.01F);
  std::bernoulli_distribution keep(0.5);
  const Eigen::Isometry3f inv = pose.inverse().cast<float>();
  std::vector<Eigen::Vector3f> out;
  for (const Eigen::Vector3f& w : world) {
    const Eigen::Vector3f p = inv * w;
    if (p.squaredNorm() > range * range || !keep(rng)) continue;
    out.emplace_back(p.x() + noise(rng), p.y() + noise(rng), p.z() + noise(rng));
  }
  return out;
}

}  // namespace adit::slam::test
