#pragma once
// Matching two time-stamped trajectories recorded at different rates.

#include <span>
#include <vector>

#include "adit/eval/path.hpp"
#include "adit/slam/trajectory.hpp"

namespace adit::eval {

// Pairs (i in ref, j in est) with |ref[i] - (est[j] + offset)| <= max_difference.
// Every stamp of the sparser trajectory is matched to its nearest stamp in the
// denser one, so each pose is used at most once and pairs are increasing in
// both indices. Both stamp lists must be non-decreasing. O(n + m).
std::vector<IndexPair> associate(std::span<const double> ref_stamps, std::span<const double> est_stamps,
                                 double max_difference, double offset = 0.0);

// The associated poses of both trajectories, in pair order.
struct Associated {
  std::vector<double> stamps;  // the reference's
  std::vector<slam::Pose> ref;
  std::vector<slam::Pose> est;
  std::vector<IndexPair> pairs;  // indices into the original trajectories
};

// Timed trajectories are matched by associate(); untimed ones (KITTI without
// times) pose by pose, which requires equal lengths (else no pairs).
Associated associate(const slam::Trajectory& ref, const slam::Trajectory& est, double max_difference, double offset = 0.0);

}  // namespace adit::eval
