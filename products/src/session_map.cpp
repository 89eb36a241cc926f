#include "adit/products/session_map.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <fmt/format.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "adit/common/error.hpp"
#include "adit/config/load.hpp"
#include "adit/products/map_thinning.hpp"
#include "adit/products/voxel_brick_set.hpp"
#include "adit/protocol/map_import.hpp"
#include "adit/slam/tum.hpp"

namespace adit::products {
namespace {

constexpr int kFixedBits = 16;  // the line-of-sight walk's fixed point: 1/65536 of a voxel
constexpr double kFixedOne = 1 << kFixedBits;

VoxelIndex voxel_of(const Eigen::Vector3f& p, float inv_voxel) {
  const auto floor_index = [](float v) { return static_cast<std::int64_t>(std::floor(v)); };
  return {floor_index(p.x() * inv_voxel), floor_index(p.y() * inv_voxel), floor_index(p.z() * inv_voxel)};
}

}  // namespace

std::filesystem::path map_file_of(const std::filesystem::path& dir) {
  for (const char* name : {"map.las", "map.ply", "map.pcd"})
    if (std::filesystem::exists(dir / name)) return dir / name;
  throw InputError((dir / "map.las").string(), "", "no map.las, map.ply or map.pcd in the session folder");
}

SessionMap rays_from(const std::vector<protocol::MapPoint>& points, const slam::Trajectory& body_poses,
                     const Eigen::Isometry3d& body_to_sensor, const RayOptions& o) {
  SessionMap m;
  m.points.reserve(points.size());
  m.intensities.reserve(points.size());
  for (const protocol::MapPoint& p : points) {
    m.points.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z));
    m.intensities.push_back(p.intensity);
  }
  m.sensor_path.reserve(body_poses.size());
  for (std::size_t i = 0; i < body_poses.size(); ++i) {
    const slam::Pose s = body_poses.poses[i] * body_to_sensor;
    m.sensor_path.push_back(body_poses.stamps[i], s);
    const Eigen::Vector3f at = s.translation().cast<float>();
    if (m.viewpoints.empty() || (at - m.viewpoints.back()).norm() >= o.path_step_m) m.viewpoints.push_back(at);
  }
  m.origin.assign(m.points.size(), -1);
  if (m.viewpoints.empty() || m.points.empty()) return m;

  const float inv_voxel = static_cast<float>(1.0 / o.voxel_m);
  VoxelBrickSet occupied(m.points.size());
  for (const Eigen::Vector3f& p : m.points) occupied.insert(voxel_of(p, inv_voxel));
  // Samples every half voxel from `from` towards `to`, up to end_clearance_m
  // short of it, walked in fixed point (voxels × 2^16): each sample adds one
  // step and its voxel is a shift, floor for negative values too.
  const double to_fixed = kFixedOne / o.voxel_m;
  const auto visible = [&](const Eigen::Vector3f& from, const Eigen::Vector3f& to) {
    const Eigen::Vector3d d = (to - from).cast<double>();
    const double length = d.norm();
    const double step = o.voxel_m / 2;
    const double stop = length - o.end_clearance_m;
    if (!(stop > step)) return true;
    const Eigen::Vector3d first = (from.cast<double>() + d * (step / length)) * to_fixed;
    const Eigen::Vector3d delta = d * (step / length * to_fixed);
    std::int64_t x = std::llround(first.x()), y = std::llround(first.y()), z = std::llround(first.z());
    const std::int64_t dx = std::llround(delta.x()), dy = std::llround(delta.y()), dz = std::llround(delta.z());
    const auto samples = static_cast<std::int64_t>(std::ceil((stop - step) / step));
    VoxelBrickSet::BrickReader reader(occupied);
    for (std::int64_t k = 0; k < samples; ++k, x += dx, y += dy, z += dz)
      if (reader.contains({x >> kFixedBits, y >> kFixedBits, z >> kFixedBits})) return false;
    return true;
  };

  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  for (const Eigen::Vector3f& v : m.viewpoints) cloud->push_back(pcl::PointXYZ(v.x(), v.y(), v.z()));
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  const int k = std::min<int>(o.candidates, static_cast<int>(m.viewpoints.size()));
  pcl::Indices nearest(static_cast<std::size_t>(k));
  std::vector<float> d2(static_cast<std::size_t>(k));
  const float max2 = static_cast<float>(o.max_range_m * o.max_range_m);
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    const Eigen::Vector3f& p = m.points[i];
    const int found = tree.nearestKSearch(pcl::PointXYZ(p.x(), p.y(), p.z()), k, nearest, d2);
    for (int j = 0; j < found; ++j) {
      if (d2[static_cast<std::size_t>(j)] > max2) break;
      const auto v = static_cast<std::int32_t>(nearest[static_cast<std::size_t>(j)]);
      if (visible(m.viewpoints[static_cast<std::size_t>(v)], p)) {
        m.origin[i] = v;
        break;
      }
    }
    m.without_ray += m.origin[i] < 0;
  }
  return m;
}

SessionInputs read_session_inputs(const std::filesystem::path& session_dir, double thin_voxel_m) {
  SessionInputs in;
  double map_voxel_m = 0.0;  // config.yaml's map.voxel_m: aditd kept one point per such voxel (0: no config)
  const std::filesystem::path config_file = session_dir / "config.yaml";
  if (std::filesystem::exists(config_file)) {
    const config::Config c = config::load_config(config_file);
    const config::Transform& e = c.lidar.extrinsics;  // xyz, then roll-pitch-yaw Z·Y·X as aditd applies it
    const double k = M_PI / 180.0;
    in.body_to_sensor.linear() = (Eigen::AngleAxisd(e.rpy_deg[2] * k, Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(e.rpy_deg[1] * k, Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(e.rpy_deg[0] * k, Eigen::Vector3d::UnitX()))
                                     .toRotationMatrix();
    in.body_to_sensor.translation() << e.xyz_m[0], e.xyz_m[1], e.xyz_m[2];
    map_voxel_m = c.map.voxel_m;
  }
  in.thin_voxel_m = thin_voxel_m < 0.0 ? map_voxel_m : thin_voxel_m;
  const std::filesystem::path map_file = map_file_of(session_dir);
  in.read_points = protocol::MapFileReader(map_file).count();
  // One pass over the file, each point the thinning keeps handed to `take`.
  const auto for_each_kept = [&](const auto& take) {
    protocol::MapFileReader reader(map_file);
    VoxelThinner thinner(in.thin_voxel_m, in.read_points);
    for (std::span<const protocol::MapPoint> block = reader.next(); !block.empty(); block = reader.next())
      for (const protocol::MapPoint& p : block)
        if (thinner.keep(p)) take(p);
  };
  // Thinned, the points kept are counted in a first pass and room made for
  // exactly them: a vector grown as they come would hold up to three times
  // their bytes while it moves (503 MB for a 60-minute drive's thinned map,
  // docs/decisions/066-loop-memory-on-long-sessions.md).
  std::size_t kept = in.read_points;
  if (in.thin_voxel_m > 0.0) {
    kept = 0;
    for_each_kept([&](const protocol::MapPoint&) { ++kept; });
  }
  in.points.reserve(kept);
  for_each_kept([&](const protocol::MapPoint& p) { in.points.push_back(p); });
  in.thinned = in.read_points - in.points.size();
  if (in.points.empty()) throw InputError(map_file.string(), "", "the map has no points");
  in.body_poses = slam::read_tum(session_dir / "map_trajectory.tum");
  return in;
}

SessionMap read_session_map(const std::filesystem::path& session_dir, const RayOptions& options) {
  const SessionInputs in = read_session_inputs(session_dir);
  return rays_from(in.points, in.body_poses, in.body_to_sensor, options);
}

}  // namespace adit::products
