#pragma once
// Checking a map against targets surveyed by total station, the way mine
// surveyors accept a map:
//  (a) relative: distances between consecutive targets, D_true vs D_map;
//  (b) absolute: per-target residuals after fitting the map onto the survey
//      frame (rigid, or similarity) on the control targets (Umeyama 1991);
//  (c) leave-one-out: each target's residual when it is not in the fit.
// Residuals are true - fitted map, so Delta = D_true - D_map has the same sign.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "adit/eval/align.hpp"

namespace adit::eval {

struct Target {
  std::string id;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

struct DistanceError {
  std::string from, to;
  double true_distance = 0.0;
  double map_distance = 0.0;
  double error = 0.0;  // D_true - D_map
  double rate = 0.0;   // error / D_true (0 when D_true = 0)
};

struct PointError {
  std::string id;
  bool control = false;
  Eigen::Vector3d delta = Eigen::Vector3d::Zero();  // true - fitted map position
  double distance = 0.0;                            // |delta|
};

struct LeaveOneOut {
  std::string id;
  std::optional<PointError> error;  // nullopt when the fit without it is not determined
};

struct TargetReport {
  std::vector<std::string> unmatched;  // ids in only one of the two files
  std::vector<DistanceError> distances;
  double distance_rmse = 0.0;
  double rate_rmse = 0.0;
  Similarity fit;  // map -> survey frame
  std::vector<PointError> points;
  Eigen::Vector3d rmse_xyz = Eigen::Vector3d::Zero();  // over all targets
  double rmse_distance = 0.0;
  std::vector<LeaveOneOut> leave_one_out;
};

// Targets are matched by id, in the order of `truth`. `control` lists the ids
// fitted on (empty: all). Throws adit::InputError when fewer than 3 control
// targets match, a control id is unknown, or they lie on one line.
TargetReport evaluate_targets(const std::vector<Target>& truth, const std::vector<Target>& map,
                              const std::vector<std::string>& control, bool with_scale);

}  // namespace adit::eval
