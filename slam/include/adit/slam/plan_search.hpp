#pragma once
// The plan-view correlative search of global localisation (Olson, ICRA 2009):
// the cloud's vertical-surface points, levelled by gravity, scored against the
// prior's plan likelihood field at every free floor cell and yaw step; for
// each yaw the best three cells, then the best few distinct peaks overall.
//
// Branch and bound over the cells (Hess, Kohler, Rapp & Andor, "Real-time
// loop closure in 2D LIDAR SLAM", ICRA 2016, section V.C): a block of
// 2^h x 2^h cells is bounded by scoring the points against a field whose
// every cell holds the maximum of the likelihood over the 2^h x 2^h cells
// from it (their precomputation grids); no cell of the block can score above
// that. Blocks are split into four while their bound can still beat the
// yaw's third best cell and a floor across yaws (a score below which no cell
// can be among the peaks kept), and at h = 0 the bound is the cell's score.
// The peaks are exactly the exhaustive search's, equal scores ordered by yaw
// and then row (tests/slam/test_plan_search.cpp); only the sums differ.
// Decision 076 has the figures.
//
// The likelihood is scored in bytes (255 levels), so that the fields of all
// levels stay in the core's caches, and a score is an exact integer sum
// (decision 077).

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "adit/slam/global_localisation.hpp"
#include "adit/slam/prior_map.hpp"

namespace adit::slam {

struct PlanPeak {
  double score = 0.0;  // mean plan likelihood of the search points (each in 1/255 steps), (0, 1]
  int ix = 0;          // the plan cell
  int iy = 0;
  double yaw = 0.0;    // rad, the cloud's frame in the prior's
};

struct PlanSearch {
  std::vector<PlanPeak> peaks;  // best first, at most config.hypotheses, pairwise distinct
  std::uint64_t sums = 0;       // bounds and cell scores computed, each a sum over the search points
  std::uint64_t cells = 0;      // candidate cells × yaw steps: what an exhaustive search sums
};

// `walls`: the cloud's vertical-surface points in its levelled frame (the
// sensor at the origin). The hint, when given, narrows the cells to its disc
// and the yaws to its range. config.search_levels: the blocks' depth (0:
// every cell scored, an exhaustive search).
PlanSearch search_plan(std::span<const Eigen::Vector3f> walls, const PlanGrid& plan,
                       const std::optional<LocalisationHint>& hint, const LocalisationConfig& config);

}  // namespace adit::slam
