#pragma once
// The floor under a ground robot's LiDAR, from its scans in the sensor frame:
// ground segmentation by sample consensus (Fischler & Bolles, CACM 24(6),
// 1981) restricted to planes near the expected vertical and below the
// sensor, refined by a least-squares fit to the inliers (the smallest
// eigenvector of their scatter). Over many scans the floor's normal is the
// body's vertical as the sensor sees it (its roll and pitch on the robot,
// the floor's bumps averaging out), and its distance the sensor's height.
// Pure.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include <Eigen/Core>

namespace adit::eval {

struct GroundOptions {
  double min_range = 0.5;          // m
  double max_range = 8.0;          // m: the floor near the robot
  double min_below = 0.2;          // m: candidates lie this far below the sensor along `up`
  double max_tilt = 0.26;          // rad (15°): a floor's normal within this of `up`
  double inlier_distance = 0.03;   // m
  std::size_t min_inliers = 200;
  unsigned iterations = 100;
  std::uint64_t seed = 1;
};

struct GroundPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, pointing up (towards the sensor), sensor frame
  double height = 0.0;                                // m: the sensor's distance above the plane
  std::size_t inliers = 0;
};

// The floor in one scan (points in the sensor frame), `up` the expected
// vertical in that frame; nullopt when no plane has min_inliers.
std::optional<GroundPlane> find_ground(std::span<const Eigen::Vector3f> points, const Eigen::Vector3d& up,
                                       const GroundOptions& options);

struct GroundSummary {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // mean of the scans' normals (outliers dropped), unit
  double angle_sd = 0.0;                              // rad: its standard error
  double height = 0.0;                                // m: median of the scans' heights
  double height_sd = 0.0;                             // m: spread (1.4826 MAD) of those
  std::size_t scans = 0;                              // scans whose floor was used
  std::size_t outliers = 0;                           // floors found but beyond 3 sigma of the median's angle
};

// The floors of many scans combined; nullopt when none was found.
std::optional<GroundSummary> combine_ground(std::span<const GroundPlane> planes);

}  // namespace adit::eval
