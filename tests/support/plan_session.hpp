#pragma once
// A session folder made from a synthetic floor (plan_scene.hpp) for the
// session-join tests: map.ply (the floor's points up to max_x) and
// trajectory.tum (a path along y = 11.5), both in a frame of the session's own.
#include <cstddef>
#include <filesystem>
#include <vector>

#include <Eigen/Geometry>

#include "adit/protocol/map_export.hpp"
#include "adit/slam/tum.hpp"

namespace adit::test {

// Returns the map's point count; the path runs x0..x1 every 0.5 m, stamped t0 + x.
inline std::size_t write_plan_session(const std::filesystem::path& dir, const std::vector<Eigen::Vector3f>& world,
                                      float max_x, double x0, double x1, double t0,
                                      const Eigen::Isometry3d& session_from_world) {
  std::filesystem::create_directories(dir);
  std::vector<protocol::MapPoint> map;
  for (const auto& p : world)
    if (p.x() <= max_x) {
      const Eigen::Vector3d q = session_from_world * p.cast<double>();
      map.push_back({q.x(), q.y(), q.z(), 10.0F, 0.0});
    }
  protocol::write_map(dir / "map.ply", protocol::MapFormat::ply, map);
  slam::Trajectory path;
  for (double x = x0; x <= x1 + 1e-9; x += 0.5)
    path.push_back(t0 + x, session_from_world * Eigen::Isometry3d(Eigen::Translation3d(x, 11.5, 0.2)));
  slam::write_tum(dir / "trajectory.tum", path);
  return map.size();
}

}  // namespace adit::test
