#include <gtest/gtest.h>

#include "adit/products/map_thinning.hpp"

namespace adit::products {
namespace {

protocol::MapPoint at(double x, double y, double z, float intensity = 0.0F) { return {x, y, z, intensity, 0.0}; }

TEST(MapThinning, KeepsTheFirstPointOfEachVoxelInTheirOrder) {
  std::vector<protocol::MapPoint> points = {
      at(0.01, 0.01, 0.01, 1),  at(0.04, 0.04, 0.04, 2),   // one 5 cm voxel: the first stays
      at(0.06, 0.01, 0.01, 3),                             // the next voxel along x
      at(-0.01, 0.01, 0.01, 4), at(-0.04, 0.02, 0.03, 5),  // below zero: its own voxel, not the first's
      at(0.03, 0.02, 0.01, 6),                             // back in the first voxel, later
  };
  EXPECT_EQ(thin_to_voxels(points, 0.05), 3U);
  ASSERT_EQ(points.size(), 3U);
  EXPECT_EQ(points[0].intensity, 1.0F);
  EXPECT_EQ(points[1].intensity, 3.0F);
  EXPECT_EQ(points[2].intensity, 4.0F);
}

TEST(MapThinning, SiteCoordinatesKeepTheirCentimetres) {
  // A map in a projected CRS (UTM: easting 500 km, northing 6,000 km): two
  // points 6 cm apart are two voxels, two 1 cm apart one (a float would hold
  // the northing to 0.5 m).
  std::vector<protocol::MapPoint> points = {at(512345.01, 6012345.01, 312.01), at(512345.07, 6012345.01, 312.01),
                                            at(512345.02, 6012345.02, 312.02)};
  EXPECT_EQ(thin_to_voxels(points, 0.05), 1U);
  ASSERT_EQ(points.size(), 2U);
  EXPECT_DOUBLE_EQ(points[1].x, 512345.07);
}

TEST(MapThinning, ZeroOrNegativeVoxelKeepsEveryPoint) {
  std::vector<protocol::MapPoint> points = {at(0, 0, 0), at(0, 0, 0)};
  EXPECT_EQ(thin_to_voxels(points, 0.0), 0U);
  EXPECT_EQ(thin_to_voxels(points, -1.0), 0U);
  EXPECT_EQ(points.size(), 2U);
  std::vector<protocol::MapPoint> none;
  EXPECT_EQ(thin_to_voxels(none, 0.05), 0U);
}

}  // namespace
}  // namespace adit::products
