#pragma once
// Synthetic floor plans for the prior-map and session-join tests: axis-aligned
// walls floor to ceiling, a floor and a ceiling, sampled on a grid with
// deterministic noise, and what a sensor sees of them.
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

namespace adit::slam::plan_scene {

struct Wall {
  double x0, y0, x1, y1;  // axis-aligned, floor to ceiling
};

// Surface points of a floor plan every `step` m: walls, floor (z = 0) and ceiling (z = 3), with deterministic noise.
inline std::vector<Eigen::Vector3f> sample_plan(const std::vector<Wall>& walls, double w, double h, double step,
                                         double noise = 0.0, std::uint64_t seed = 1) {
  std::uint64_t state = seed;
  const auto jitter = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return noise * (static_cast<double>(state >> 11) * 0x1.0p-53 - 0.5) * 2.0;
  };
  std::vector<Eigen::Vector3f> out;
  for (const Wall& wall : walls) {
    const double len = std::hypot(wall.x1 - wall.x0, wall.y1 - wall.y0);
    const bool along_x = std::abs(wall.y1 - wall.y0) < 1e-9;
    for (double s = 0; s <= len; s += step)
      for (double z = 0; z <= 3.0; z += step) {
        const double x = wall.x0 + (wall.x1 - wall.x0) * s / len, y = wall.y0 + (wall.y1 - wall.y0) * s / len;
        out.emplace_back(static_cast<float>(x + (along_x ? 0.0 : jitter())), static_cast<float>(y + (along_x ? jitter() : 0.0)),
                         static_cast<float>(z));
      }
  }
  for (double x = 0; x <= w; x += step)
    for (double y = 0; y <= h; y += step) {
      out.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(jitter()));
      out.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(3.0 + jitter()));
    }
  return out;
}

inline void add_box(std::vector<Wall>& walls, double x, double y, double r) {
  walls.push_back({x - r, y - r, x + r, y - r});
  walls.push_back({x + r, y - r, x + r, y + r});
  walls.push_back({x + r, y + r, x - r, y + r});
  walls.push_back({x - r, y + r, x - r, y - r});
}

// 24 x 16 m, rooms and pillars placed with no symmetry.
inline std::vector<Wall> office(double moved = 0.0) {
  std::vector<Wall> walls{{0, 0, 24, 0}, {24, 0, 24, 16}, {24, 16, 0, 16}, {0, 16, 0, 0},
                          {8 + moved, 0, 8 + moved, 10}, {8, 13, 8, 16}, {16, 6, 24, 6}, {16, 6, 16, 3}};
  add_box(walls, 4, 12, 0.3);
  add_box(walls, 12, 4, 0.3);
  add_box(walls, 20, 11, 0.3);
  return walls;
}

inline Eigen::Isometry3d pose_at(double x, double y, double yaw) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(x, y, 1.2);
  return t;
}

// What a sensor at `pose` sees within `range` (no occlusion), in its levelled frame.
inline std::vector<Eigen::Vector3f> cloud_at(const std::vector<Eigen::Vector3f>& world, const Eigen::Isometry3d& pose, float range) {
  const Eigen::Isometry3f inv = pose.inverse().cast<float>();
  std::vector<Eigen::Vector3f> out;
  for (const auto& p : world) {
    const Eigen::Vector3f q = inv * p;
    if (q.norm() < range) out.push_back(q);
  }
  return out;
}

// 48 x 16 m: the office on the left (x < 24), a door at x = 24 (y 10-13),
// another layout on the right: two sessions' worth of floor.
inline std::vector<Wall> two_halves() {
  std::vector<Wall> walls = office();
  walls.erase(walls.begin() + 1);  // the office's east wall, replaced by one with a door
  for (const Wall& w : std::vector<Wall>{{24, 0, 24, 10}, {24, 13, 24, 16}, {24, 0, 48, 0}, {48, 0, 48, 16},
                                         {48, 16, 24, 16}, {32, 0, 32, 7}, {40, 16, 40, 13}})
    walls.push_back(w);
  add_box(walls, 36, 4, 0.4);
  add_box(walls, 44, 14, 0.3);
  add_box(walls, 29, 13.5, 0.5);
  return walls;
}

// Another floor, 30 x 20 m, nothing like the office.
inline std::vector<Wall> other_building() {
  std::vector<Wall> other{{0, 0, 30, 0}, {30, 0, 30, 20}, {30, 20, 0, 20}, {0, 20, 0, 0}, {15, 0, 15, 7}};
  add_box(other, 7, 14, 1.0);
  add_box(other, 23, 9, 0.5);
  return other;
}

// A level frame: turned by yaw about z, then moved.
inline Eigen::Isometry3d level_frame(double x, double y, double z, double yaw) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(x, y, z);
  return t;
}

}  // namespace adit::slam::plan_scene
