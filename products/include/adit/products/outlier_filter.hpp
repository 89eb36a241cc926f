#pragma once
// Statistical outlier removal (Rusu et al., "Towards 3D point cloud based
// object maps for household environments", RAS 2008, section 4): a point
// whose mean distance to its k nearest neighbours exceeds the mean of those
// distances over the cloud by more than stddev_mult standard deviations is an
// outlier. PCL's implementation (pcl::StatisticalOutlierRemoval); PCL stays
// inside the .cpp.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace adit::products {

struct OutlierOptions {
  int k = 15;                 // neighbours (the seed's k = 15)
  double stddev_mult = 1.0;   // γ; the seed's 0.2 removes a quarter of the non-ground points (docs/PRODUCTS.md)
};

// 1 for each point kept among those with mask[i] != 0; points outside the mask are 0.
std::vector<std::uint8_t> statistical_inliers(std::span<const Eigen::Vector3f> points,
                                              std::span<const std::uint8_t> mask, const OutlierOptions& options);

}  // namespace adit::products
