// adit eval map: how far the map's points lie from the true scene surfaces
// (absolute point error, as surveyors judge a map). docs/EVALUATION.md
// defines the figures.

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "adit/common/error.hpp"
#include "adit/protocol/map_import.hpp"
#include "adit/protocol/ply_mesh.hpp"
#include "adit/eval/align.hpp"
#include "adit/eval/associate.hpp"
#include "adit/eval/interpolate.hpp"
#include "adit/eval/mesh_distance.hpp"
#include "adit/eval/trajectory_io.hpp"
#include "eval_commands.hpp"

namespace adit::tools {

std::vector<eval::Triangle> scene_triangles(const std::string& file) {
  const protocol::PlyMesh mesh = protocol::read_ply_mesh(file);
  if (mesh.triangles.empty()) throw InputError(file, "element face", "the scene has no triangles");
  const auto vertex = [&](std::uint32_t i) {
    return Eigen::Vector3d(mesh.vertices[i][0], mesh.vertices[i][1], mesh.vertices[i][2]);
  };
  std::vector<eval::Triangle> out;
  out.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) out.push_back({vertex(t[0]), vertex(t[1]), vertex(t[2])});
  return out;
}

slam::Trajectory timed_trajectory(const std::string& file) {
  slam::Trajectory t = eval::read_trajectory(file, eval::detect_trajectory_format(file));
  if (t.empty() || !t.timed) throw InputError(file, "", "needs time-stamped poses");
  return t;
}

// The map frame is the estimate's: its first pose est(t0) is where the body
// was at t0, which the reference says is ref(t0) in the world. So a map point
// p goes to ref(t0) · est(t0)⁻¹ · p.
Eigen::Isometry3d world_from_map(const std::string& ref_file, const std::string& est_file) {
  const slam::Trajectory ref = timed_trajectory(ref_file);
  const slam::Trajectory est = timed_trajectory(est_file);
  const double t0 = est.stamps.front();
  const auto ref_t0 = eval::interpolate_pose(ref, t0);
  if (!ref_t0)
    throw InputError(ref_file, "",
                     fmt::format("t0 = {:.6f} s (first stamp of {}) is outside the reference's "
                                 "{:.6f} .. {:.6f} s",
                                 t0, est_file, ref.stamps.front(), ref.stamps.back()));
  return *ref_t0 * est.poses.front().inverse();
}

// The rigid transform that best lays the estimate's positions onto the
// reference's (Umeyama, align.hpp), as a surveyor fits a map to control
// points: a tilt or heading error the whole map shares does not count.
Eigen::Isometry3d world_from_map_fitted(const std::string& ref_file, const std::string& est_file, std::size_t& poses) {
  constexpr double kMaxDifference = 0.01;  // s, as adit eval traj
  const eval::Associated a = eval::associate(timed_trajectory(ref_file), timed_trajectory(est_file), kMaxDifference);
  const auto fit = eval::align_trajectory(a.ref, a.est, eval::Alignment::se3);
  if (!fit)
    throw InputError(est_file, "",
                     fmt::format("{} poses matched to {} within {} s: too few, or all on one line, for a rigid fit",
                                 a.est.size(), ref_file, kMaxDifference));
  poses = a.est.size();
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = fit->rotation;
  t.translation() = fit->translation;
  return t;
}

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// `placement` with its rotation cut to the turn about the vertical nearest
// it (the yaw ψ minimising ‖Rz(ψ) − R‖_F), still taking `origin` (the first
// pose's position, map frame) where `placement` takes it: the map keeps its
// own tilt, as a crew without control points gets it.
Eigen::Isometry3d turned_about_the_vertical(const Eigen::Isometry3d& placement, const Eigen::Vector3d& origin) {
  const Eigen::Matrix3d& r = placement.linear();
  const double yaw = std::atan2(r(1, 0) - r(0, 1), r(0, 0) + r(1, 1));
  Eigen::Isometry3d turned = Eigen::Isometry3d::Identity();
  turned.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  turned.translation() = placement * origin - turned.linear() * origin;
  return turned;
}

struct Placement {
  Eigen::Isometry3d world_from_map = Eigen::Isometry3d::Identity();
  double t0 = 0.0;  // s; the estimate's first stamp when placed by its origin
  bool by_trajectories = false;
  std::size_t fitted_poses = 0;  // poses of the fit when placed by a rigid fit (se3)
};

Placement placement(const MapEvalOptions& o) {
  Placement p;
  if (o.ref.empty()) return p;
  p.by_trajectories = true;
  if (o.align == "se3") {
    p.world_from_map = world_from_map_fitted(o.ref, o.est, p.fitted_poses);
    return p;
  }
  const slam::Trajectory est = timed_trajectory(o.est);
  p.t0 = est.stamps.front();
  p.world_from_map = world_from_map(o.ref, o.est);
  if (o.align == "heading") p.world_from_map = turned_about_the_vertical(p.world_from_map, est.poses.front().translation());
  return p;
}

struct MapAccuracy {
  std::size_t points = 0;
  std::size_t within = 0;      // distance <= the threshold
  std::size_t beyond_cap = 0;  // no triangle closer than the cap
  double median = 0.0;         // +inf when the middle lies beyond the cap
  double p95 = 0.0;            // nearest rank; +inf likewise
  double mean = 0.0;           // of the distances below the cap
};

// `d` is reordered. Median as compute_stats (mean of the two middle values for
// an even count); p95 by nearest rank, the ceil(0.95 n)-th smallest.
MapAccuracy summarize(std::vector<double>& d, double within) {
  MapAccuracy a;
  a.points = d.size();
  double sum = 0.0;
  for (const double v : d) {
    if (v <= within) ++a.within;
    if (std::isinf(v)) {
      ++a.beyond_cap;
    } else {
      sum += v;
    }
  }
  const std::size_t below = a.points - a.beyond_cap;
  a.mean = below > 0 ? sum / static_cast<double>(below) : kInfinity;
  const auto kth = [&](std::size_t k) {
    std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(k), d.end());
    return d[k];
  };
  const std::size_t n = d.size();
  a.median = n % 2 == 1 ? kth(n / 2) : 0.5 * (kth(n / 2 - 1) + kth(n / 2));
  a.p95 = kth(static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(n))) - 1);
  return a;
}

// The points in one contiguous slice per core; MeshDistance is read-only.
std::vector<double> distances_in_parallel(const eval::MeshDistance& scene, std::span<const Eigen::Vector3d> points) {
  const std::size_t slices = std::clamp<std::size_t>(std::thread::hardware_concurrency(), 1,
                                                     std::max<std::size_t>(1, points.size() / 100'000));
  std::vector<std::vector<double>> parts(slices);
  {
    std::vector<std::jthread> workers;
    for (std::size_t k = 0; k < slices; ++k) {
      const std::size_t begin = points.size() * k / slices, end = points.size() * (k + 1) / slices;
      workers.emplace_back([&, k, begin, end] { parts[k] = scene.distances(points.subspan(begin, end - begin)); });
    }
  }  // joined
  std::vector<double> out;
  out.reserve(points.size());
  for (const auto& part : parts) out.insert(out.end(), part.begin(), part.end());
  return out;
}

nlohmann::json metres_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

std::string metres_or_beyond(double v, double cap) {
  return std::isfinite(v) ? fmt::format("{:.4f} m", v) : fmt::format("> {:g} m (cap)", cap);
}

}  // namespace

void run_eval_map(const MapEvalOptions& o) {
  if (o.within > o.cap)
    throw InputError("", "--within",
                     fmt::format("{} m is beyond --cap {} m, where distances are not computed", o.within, o.cap));
  const eval::MeshDistance scene(scene_triangles(o.scene), o.cap);
  const Placement place = placement(o);
  // Only the placed positions are kept (a 5 M-point map's fields are 200 MB).
  const std::vector<Eigen::Vector3d> points = [&] {
    const std::vector<protocol::MapPoint> map = protocol::read_map(o.map);
    if (map.empty()) throw InputError(o.map, "", "the map has no points");
    std::vector<Eigen::Vector3d> placed;
    placed.reserve(map.size());
    for (const protocol::MapPoint& p : map) placed.push_back(place.world_from_map * Eigen::Vector3d(p.x, p.y, p.z));
    return placed;
  }();
  std::vector<double> distances = distances_in_parallel(scene, points);
  const MapAccuracy a = summarize(distances, o.within);
  const double fraction = static_cast<double>(a.within) / static_cast<double>(a.points);
  // How far the placement turned the map's z from the scene's vertical: the
  // map's own tilt from gravity, which a placement by the trajectories
  // removes (origin: with the reference's first attitude) and a map without
  // one keeps.
  const double map_tilt_deg =
      std::acos(std::clamp((place.world_from_map.linear() * Eigen::Vector3d::UnitZ()).z(), -1.0, 1.0)) * 180.0 /
      std::numbers::pi;

  if (o.json) {
    const nlohmann::json j{{"points", a.points},
                           {"within_m", o.within},
                           {"fraction_within", fraction},
                           {"median_m", metres_or_null(a.median)},
                           {"p95_m", metres_or_null(a.p95)},
                           {"mean_m", metres_or_null(a.mean)},
                           {"beyond_cap", a.beyond_cap},
                           {"cap_m", o.cap},
                           {"placement", !place.by_trajectories ? "none" : o.align},
                           {"map_tilt_deg", map_tilt_deg}};
    fmt::print("{}\n", j.dump(2));
    return;
  }
  fmt::print("map               {} ({} points)\n", o.map, a.points);
  fmt::print("scene             {} ({} triangles)\n", o.scene, scene.size());
  if (place.fitted_poses > 0) {
    const Eigen::Vector3d t = place.world_from_map.translation();
    fmt::print("placement         se3 fit of {} poses of the estimate to the reference: map origin at ({:.3f}, {:.3f}, {:.3f}) m\n",
               place.fitted_poses, t.x(), t.y(), t.z());
  } else if (place.by_trajectories) {
    const Eigen::Vector3d t = place.world_from_map.translation();
    fmt::print("placement         ref(t0) est(t0)^-1 at t0 = {:.6f} s{}: map origin at ({:.3f}, {:.3f}, {:.3f}) m\n",
               place.t0, o.align == "heading" ? ", turned about the vertical only" : "", t.x(), t.y(), t.z());
  } else {
    fmt::print("placement         none (map taken as in the scene frame)\n");
  }
  if (place.by_trajectories)
    fmt::print("map tilt          {:.3f}° (the map's z from the vertical, removed by the placement)\n", map_tilt_deg);
  fmt::print("within {:.3f} m    {:.2f} % ({} points)\n", o.within, 100.0 * fraction, a.within);
  fmt::print("median            {}\n", metres_or_beyond(a.median, o.cap));
  fmt::print("p95               {}\n", metres_or_beyond(a.p95, o.cap));
  fmt::print("mean below cap    {}\n", metres_or_beyond(a.mean, o.cap));
  fmt::print("beyond cap {:g} m  {} points ({:.2f} %)\n", o.cap, a.beyond_cap,
             100.0 * static_cast<double>(a.beyond_cap) / static_cast<double>(a.points));
}

}  // namespace adit::tools
