#include <gtest/gtest.h>

#include <vector>

#include "adit/products/outlier_filter.hpp"

namespace adit::products {
namespace {

TEST(OutlierFilter, IsolatedPointsGoAWallStays) {
  std::vector<Eigen::Vector3f> points;
  for (float y = 0; y < 5; y += 0.05F)
    for (float z = 0; z < 2; z += 0.05F) points.emplace_back(0.0F, y, z);
  const std::size_t wall = points.size();
  points.emplace_back(1.5F, 2.0F, 1.0F);  // returns in mid-air, far from everything
  points.emplace_back(-2.0F, 1.0F, 0.5F);
  points.emplace_back(0.8F, 4.0F, 1.7F);
  const std::vector<std::uint8_t> mask(points.size(), 1);
  const std::vector<std::uint8_t> keep = statistical_inliers(points, mask, OutlierOptions{});
  std::size_t kept_wall = 0;
  for (std::size_t i = 0; i < wall; ++i) kept_wall += keep[i];
  EXPECT_GT(kept_wall, 0.97 * wall);
  for (std::size_t i = wall; i < points.size(); ++i) EXPECT_EQ(keep[i], 0) << i;
}

TEST(OutlierFilter, PointsOutsideTheMaskAreNotKept) {
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 100; ++i) points.emplace_back(0.01F * i, 0.0F, 0.0F);
  std::vector<std::uint8_t> mask(points.size(), 1);
  mask[10] = 0;
  const std::vector<std::uint8_t> keep = statistical_inliers(points, mask, OutlierOptions{});
  EXPECT_EQ(keep[10], 0);
  EXPECT_EQ(keep[50], 1);
}

}  // namespace
}  // namespace adit::products
