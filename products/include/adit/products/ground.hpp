#pragma once
// Ground segmentation by patch-wise plane fitting: the ground is not one plane
// underground (floors undulate, ramps), so the map is cut into square patches
// and a plane is fitted to each patch's lowest points, as Patchwork does with
// its concentric zones (Lim et al., RA-L 2021) and as the seed systems' single
// plane fit does (0.12 m threshold) within one patch. A patch whose fitted
// plane is steeper than max_slope_deg (a wall), or which stands well above
// its neighbours (a desk top seen without the floor under it), has no ground
// of its own and takes its nearest neighbour's plane.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace adit::products {

struct GroundOptions {
  double patch_m = 1.0;          // side of a patch
  double seed_band_m = 0.30;     // the lowest points of a patch within this of its lowest seed the fit
  double distance_m = 0.12;      // a point this close to its patch's plane is ground (the seed's threshold)
  double max_slope_deg = 25.0;   // steeper planes are walls, not floor
  double max_step_m = 0.30;      // a patch higher than its neighbours' median by more is not ground
};

class GroundModel {
 public:
  GroundModel() = default;
  GroundModel(Eigen::Vector2d origin, double patch_m, int nx, int ny, std::vector<Eigen::Vector3d> planes,
              std::vector<std::uint8_t> fitted);
  // Height of the ground under (x, y): its patch's plane z = a x + b y + c
  // (the nearest patch's outside the map). 0 for an empty model.
  double height_at(double x, double y) const;
  bool empty() const { return planes_.empty(); }
  int fitted_patches() const;

 private:
  Eigen::Vector2d origin_{0.0, 0.0};
  double patch_m_ = 1.0;
  int nx_ = 0, ny_ = 0;
  std::vector<Eigen::Vector3d> planes_;  // (a, b, c) per patch, row-major from origin
  std::vector<std::uint8_t> fitted_;     // 1 where the patch had ground of its own
};

struct GroundSegmentation {
  GroundModel model;
  std::vector<std::uint8_t> is_ground;  // per point
  std::size_t ground_points = 0;
};

GroundSegmentation segment_ground(std::span<const Eigen::Vector3f> points, const GroundOptions& options);

}  // namespace adit::products
