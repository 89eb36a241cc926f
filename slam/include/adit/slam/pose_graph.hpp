#pragma once
// The pose graph's data: keyframe poses (nodes), relative-pose edges from the
// odometry and from verified loops, and optional roll/pitch priors from
// gravity. Plain values, no solver: slam/pose_graph_solver.hpp optimises it
// with Ceres (factors in slam/src/pose_graph_factors.hpp), as small_gicp keeps
// its data, factors and solvers apart.
//
// An edge from a to b measures T_a⁻¹·T_b; its information is of the error
// e = [p_err; θ_err] in a's frame, twist order [v; ω] like the rest of slam/
// (the residual is written in pose_graph_factors.hpp). Loop edges carry a
// robust kernel in the solver (a false loop that passed every check is
// down-weighted, not obeyed), odometry edges none.

#include <cstddef>
#include <vector>

#include <Eigen/Geometry>

#include "adit/slam/lie.hpp"

namespace adit::slam {

enum class EdgeKind { odometry, loop };

struct PoseGraphEdge {
  std::size_t from = 0;
  std::size_t to = 0;
  Eigen::Isometry3d measurement = Eigen::Isometry3d::Identity();  // T_from⁻¹·T_to
  Matrix6d information = Matrix6d::Identity();
  EdgeKind kind = EdgeKind::odometry;
};

// R·up_body should be +z of the map: holds roll and pitch, leaves yaw.
struct GravityPriorEdge {
  std::size_t node = 0;
  Eigen::Vector3d up_body = Eigen::Vector3d::UnitZ();
  double information = 0.0;  // 1/σ², σ the tilt error in rad
  double stamp_s = 0.0;      // when it was measured (the tilt walk's time step)
};

// A node's pose measured in the graph's own frame: a keyframe mapped while
// the odometry was registered against a prior map (slam::PriorMapTerm) is
// placed by that prior, not by the chain of odometry before it.
struct AbsolutePoseEdge {
  std::size_t node = 0;
  Eigen::Isometry3d measurement = Eigen::Isometry3d::Identity();
  Matrix6d information = Matrix6d::Identity();
};

struct PoseGraph {
  // Node 0 is held fixed, defining the map frame, unless absolute edges do.
  std::vector<Eigen::Isometry3d> nodes;
  std::vector<PoseGraphEdge> edges;
  std::vector<GravityPriorEdge> gravity;
  std::vector<AbsolutePoseEdge> absolute;
  // The measured ups may be off by a tilt that wanders: an accelerometer's
  // bias b walks (its random walk, in m/s³/√Hz), and the up it gives is off
  // by b/g rad. > 0: each gravity prior's up is turned by a tilt offset δ
  // (about the body's x and y axes, where the bias lives) that walks between
  // consecutive priors with σ = this·√Δt, the first held at zero (it defines
  // the map's level with node 0). Loops that close in height then tell the
  // graph the tilt, as bias states do in visual-inertial graphs (Forster et
  // al., T-RO 2017, eq. 40). 0 = the ups as measured.
  double tilt_walk_rad_per_sqrt_s = 0.0;
  std::vector<Eigen::Vector2d> tilt_offsets;  // per gravity prior, after optimize() (and its next start)

  std::size_t loop_count() const {
    std::size_t n = 0;
    for (const PoseGraphEdge& e : edges) n += e.kind == EdgeKind::loop ? 1 : 0;
    return n;
  }
};

// The information of an odometry edge over `distance_m` and `angle_rad` of
// motion, from a drift model: σ_t = floor + rate·distance per axis, σ_r alike.
// (The registration's own covariance is optimistic, Censi ICRA 2007; the map
// poses drift 0.02-0.07 % of the path on the bench drives, docs/ODOMETRY.md,
// so 1 % per metre is loose enough to let a loop move them.)
struct OdometryNoise {
  double sigma_floor_m = 0.01;
  double sigma_per_m = 0.01;
  double sigma_floor_rad = 0.001;
  double sigma_rad_per_m = 0.0005;
  double sigma_rad_per_rad = 0.01;
};
Matrix6d odometry_information(const Eigen::Isometry3d& motion, const OdometryNoise& noise = {});

}  // namespace adit::slam
