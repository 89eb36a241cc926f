// Ceres optimisation of a pose graph (pose_graph_solver.hpp).
#include "adit/slam/pose_graph_solver.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Cholesky>

#include "pose_graph_factors.hpp"

namespace adit::slam {
namespace {

Matrix6d sqrt_information(const Matrix6d& information) {
  // Λ = LLᵀ (Cholesky), whitening with Lᵀ: eᵀΛe = |Lᵀe|².
  const Eigen::LLT<Matrix6d> llt(information);
  return llt.matrixL().transpose();
}

}  // namespace

PoseGraphSolution optimize(PoseGraph& graph, const PoseGraphSolverConfig& config) {
  PoseGraphSolution solution;
  const std::size_t n = graph.nodes.size();
  if (n < 2) {
    solution.converged = true;
    return solution;
  }
  // Parameters: per node a quaternion (x, y, z, w) and a translation.
  std::vector<Eigen::Quaterniond> q(n);
  std::vector<Eigen::Vector3d> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    q[i] = Eigen::Quaterniond(graph.nodes[i].linear()).normalized();
    p[i] = graph.nodes[i].translation();
  }
  ceres::Problem problem;
  for (const PoseGraphEdge& e : graph.edges) {
    if (e.from >= n || e.to >= n || e.from == e.to) continue;
    ceres::LossFunction* loss =
        e.kind == EdgeKind::loop ? new ceres::CauchyLoss(config.loop_kernel_scale) : nullptr;  // owned by problem
    problem.AddResidualBlock(detail::RelativePoseFactor::create(e.measurement, sqrt_information(e.information)), loss,
                             q[e.from].coeffs().data(), p[e.from].data(), q[e.to].coeffs().data(), p[e.to].data());
  }
  for (const AbsolutePoseEdge& a : graph.absolute) {
    if (a.node >= n) continue;
    problem.AddResidualBlock(detail::AbsolutePoseFactor::create(a.measurement, sqrt_information(a.information)), nullptr,
                             q[a.node].coeffs().data(), p[a.node].data());
  }
  // Tilt offsets (PoseGraph::tilt_walk_rad_per_sqrt_s), started from the last solve's.
  const bool walk = graph.tilt_walk_rad_per_sqrt_s > 0.0 && !graph.gravity.empty();
  std::vector<Eigen::Vector2d> delta(walk ? graph.gravity.size() : 0, Eigen::Vector2d::Zero());
  for (std::size_t i = 0; i < std::min(delta.size(), graph.tilt_offsets.size()); ++i) delta[i] = graph.tilt_offsets[i];
  for (std::size_t i = 0; i < graph.gravity.size(); ++i) {
    const GravityPriorEdge& g = graph.gravity[i];
    if (g.node >= n || g.information <= 0.0) continue;
    if (!walk) {
      problem.AddResidualBlock(detail::GravityFactor::create(g.up_body, g.information), nullptr,
                               q[g.node].coeffs().data());
      continue;
    }
    problem.AddResidualBlock(detail::TiltedGravityFactor::create(g.up_body, g.information), nullptr,
                             q[g.node].coeffs().data(), delta[i].data());
    if (i == 0) continue;
    const double dt = std::max(graph.gravity[i].stamp_s - graph.gravity[i - 1].stamp_s, 1e-3);
    problem.AddResidualBlock(detail::TiltWalkFactor::create(graph.tilt_walk_rad_per_sqrt_s * std::sqrt(dt)), nullptr,
                             delta[i - 1].data(), delta[i].data());
  }
  if (walk && problem.HasParameterBlock(delta[0].data())) problem.SetParameterBlockConstant(delta[0].data());
  for (std::size_t i = 0; i < n; ++i) {
    if (!problem.HasParameterBlock(q[i].coeffs().data())) {
      problem.AddParameterBlock(q[i].coeffs().data(), 4);
      problem.AddParameterBlock(p[i].data(), 3);
    }
    problem.SetManifold(q[i].coeffs().data(), new ceres::EigenQuaternionManifold);  // owned by problem
  }
  const bool placed = std::any_of(graph.absolute.begin(), graph.absolute.end(),
                                  [n](const AbsolutePoseEdge& a) { return a.node < n; });
  if (!placed) {  // else the absolute edges fix the frame, and node 0 moves with the rest
    problem.SetParameterBlockConstant(q[0].coeffs().data());
    problem.SetParameterBlockConstant(p[0].data());
  }

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = config.max_iterations;
  options.max_solver_time_in_seconds = config.max_time_s;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  solution.converged = summary.termination_type == ceres::CONVERGENCE;
  solution.iterations = static_cast<int>(summary.iterations.size());
  solution.initial_cost = summary.initial_cost;
  solution.final_cost = summary.final_cost;
  solution.time_s = summary.total_time_in_seconds;
  for (std::size_t i = 0; i < n; ++i) {
    graph.nodes[i].linear() = q[i].normalized().toRotationMatrix();
    graph.nodes[i].translation() = p[i];
  }
  graph.tilt_offsets = delta;
  for (const PoseGraphEdge& e : graph.edges) {
    if (e.kind != EdgeKind::loop || e.from >= n || e.to >= n) continue;
    const Eigen::Isometry3d err = e.measurement.inverse() * graph.nodes[e.from].inverse() * graph.nodes[e.to];
    const Vector6d v = log_se3(err);
    solution.loop_residuals.push_back(std::sqrt(v.dot(e.information * v)));
  }
  return solution;
}

}  // namespace adit::slam
