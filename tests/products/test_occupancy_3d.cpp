#include <gtest/gtest.h>

#include <filesystem>
#include <vector>

#include "adit/products/occupancy_3d.hpp"

namespace adit::products {
namespace {

using State = Occupancy3d::State;

TEST(Occupancy3d, RaysClearTheWayAndMarkTheirEnd) {
  Occupancy3d map(Occupancy3dOptions{});
  std::vector<Eigen::Vector3f> wall;
  for (float y = -1; y <= 1; y += 0.05F) wall.emplace_back(3.0F, y, 0.0F);
  map.insert(Eigen::Vector3f(0.02F, 0.02F, 0.02F), wall, {});
  EXPECT_EQ(map.state_at({1.5F, 0.0F, 0.0F}), State::free);
  EXPECT_EQ(map.state_at({3.0F, 0.0F, 0.0F}), State::occupied);
  EXPECT_EQ(map.state_at({4.0F, 0.0F, 0.0F}), State::unknown);  // behind the wall
  EXPECT_EQ(map.state_at({1.5F, 0.0F, 2.0F}), State::unknown);  // no ray went there
}

TEST(Occupancy3d, PassesClearWithoutMarking) {
  Occupancy3d map(Occupancy3dOptions{});
  const std::vector<Eigen::Vector3f> ground = {{2.01F, 0.01F, -0.99F}};  // off the voxels' boundaries
  map.insert(Eigen::Vector3f(0.01F, 0.01F, 0.51F), {}, ground);
  EXPECT_EQ(map.state_at({1.01F, 0.01F, -0.24F}), State::free);
  EXPECT_NE(map.state_at(ground[0]), State::occupied);
}

TEST(Occupancy3d, SomethingThatLeftIsClearedByLaterRays) {
  Occupancy3d map(Occupancy3dOptions{});
  const std::vector<Eigen::Vector3f> person = {{2.0F, 0.0F, 0.0F}};
  const std::vector<Eigen::Vector3f> wall = {{5.0F, 0.0F, 0.0F}};
  map.insert(Eigen::Vector3f::Zero(), person, {});
  EXPECT_EQ(map.state_at(person[0]), State::occupied);
  for (int k = 0; k < 3; ++k) map.insert(Eigen::Vector3f::Zero(), wall, {});
  EXPECT_EQ(map.state_at(person[0]), State::free);
  EXPECT_EQ(map.state_at(wall[0]), State::occupied);
}

TEST(Occupancy3d, WritesBinaryTree) {
  Occupancy3d map(Occupancy3dOptions{});
  const std::vector<Eigen::Vector3f> wall = {{2.0F, 0.0F, 0.0F}};
  map.insert(Eigen::Vector3f::Zero(), wall, {});
  const auto file = std::filesystem::temp_directory_path() / "adit_test_occupancy.bt";
  const std::uintmax_t bytes = map.write_bt(file);
  EXPECT_GT(bytes, 0u);
  EXPECT_EQ(bytes, std::filesystem::file_size(file));
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace adit::products
