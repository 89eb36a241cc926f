#pragma once
// Optimises a PoseGraph (slam/pose_graph.hpp) with Ceres: Levenberg-Marquardt
// on the poses, sparse Cholesky, one thread (the graph runs in the background
// on the payload's spare core share). Loop edges go through a Cauchy kernel
// (robust kernel against a false loop that passed verification: Sünderhauf &
// Protzel's switchable constraints, IROS 2012, and Agarwal et al.'s dynamic
// covariance scaling, ICRA 2013, both reduce to such a kernel; we use the
// plain kernel, the simplest that bounds a wrong loop's pull).

#include <cstddef>

#include "adit/slam/pose_graph.hpp"

namespace adit::slam {

struct PoseGraphSolverConfig {
  int max_iterations = 50;
  double loop_kernel_scale = 3.0;  // Cauchy scale on the whitened loop residual (≈ σ units)
  double max_time_s = 1.0;
};

struct PoseGraphSolution {
  bool converged = false;
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  double time_s = 0.0;
  // After the solve, per loop edge in graph order: its whitened residual norm
  // (in σ); a loop the kernel down-weighted stands out.
  std::vector<double> loop_residuals;
};

// Moves graph.nodes (node 0 held fixed) to the optimum.
PoseGraphSolution optimize(PoseGraph& graph, const PoseGraphSolverConfig& config = {});

}  // namespace adit::slam
