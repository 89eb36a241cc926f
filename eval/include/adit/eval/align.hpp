#pragma once
// Least-squares alignment of one point set (or trajectory) onto another:
// rotation, translation and optionally scale, by Umeyama's closed form
//   S. Umeyama, "Least-squares estimation of transformation parameters between
//   two point patterns", IEEE TPAMI 13(4):376-380, 1991.

#include <optional>
#include <span>
#include <string_view>

#include <Eigen/Core>

#include "adit/slam/trajectory.hpp"

namespace adit::eval {

// y = scale * rotation * x + translation
struct Similarity {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1.0;

  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return scale * (rotation * x) + translation; }
  // Moves a whole pose: its rotation is turned, its position transformed.
  slam::Pose apply(const slam::Pose& pose) const;
};

// The transform minimising sum |to_i - (s R from_i + t)|^2 (Umeyama eqs. 40-42;
// s = 1 unless with_scale). nullopt when the points cannot fix a rotation:
// fewer than 3, or all on one line (rank of the covariance below 2, the
// condition under Umeyama's eq. 43).
std::optional<Similarity> umeyama_fit(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to, bool with_scale);

enum class Alignment { none, origin, se3, sim3 };

// "none", "origin", "se3", "sim3"; nullopt for anything else.
std::optional<Alignment> parse_alignment(std::string_view name);
std::string_view alignment_name(Alignment alignment);

// The transform taking `est` onto `ref` (matched pose by pose): identity for
// none; ref[0] * est[0]^-1 for origin; Umeyama on the positions for se3/sim3.
// nullopt when se3/sim3 positions are degenerate (see umeyama_fit()).
std::optional<Similarity> align_trajectory(std::span<const slam::Pose> ref, std::span<const slam::Pose> est, Alignment alignment);

}  // namespace adit::eval
