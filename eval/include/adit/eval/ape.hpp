#pragma once
// Absolute pose error (Sturm et al., "A benchmark for the evaluation of RGB-D
// SLAM systems", IROS 2012, sec. VI-B): for matched poses Q_i (reference) and
// P_i (estimate, already aligned), E_i = Q_i^-1 P_i; the translation error is
// |trans(E_i)| = |t_Q - t_P| and the rotation error the angle of rot(E_i).

#include <span>

#include "adit/eval/pose_error.hpp"
#include "adit/slam/trajectory.hpp"

namespace adit::eval {

// ref and est have the same length (associated pose by pose).
PoseErrors absolute_pose_errors(std::span<const slam::Pose> ref, std::span<const slam::Pose> est);

}  // namespace adit::eval
